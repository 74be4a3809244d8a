#!/usr/bin/env bash
# One network, quantile heads and a 5-member ensemble, trained on the same data set with the
# same protocol, each timed and evaluated on the test seed: coverage of the 90 % interval and
# its mean width (issue 36: which is better per unit of training time).
#   examples/compare_uncertainty.sh [DATA] [OUT]     (DATA: generate --plan demo --snr-db 6)
set -euo pipefail
R=${RAILFORCE:-target/release/railforce}
D=${1:-data/demo}
O=${2:-models/compare_uncertainty}
mkdir -p "$O"
for cfg in "single:" "quantile-heads:--quantile-heads" "ensemble5:--ensemble 5"; do
  name=${cfg%%:*}; args=${cfg#*:}
  t0=$(date +%s.%N)
  # shellcheck disable=SC2086
  "$R" train --data "$D" --model cnn-bilstm --centre-label --out "$O/$name" --force $args > "$O/$name.train.log" 2>&1
  t1=$(date +%s.%N)
  "$R" evaluate --model "$O/$name" --data "$D" > "$O/$name.eval.log" 2>&1
  printf '%s: trained in %.0f s; pooled R² %s; %s\n' "$name" "$(echo "$t1 - $t0" | bc)" \
    "$(grep -E '^all \(pooled\)' "$O/$name.eval.log" | awk '{printf "%s %s ", $3, $6}')" \
    "$(tail -1 "$O/$name.eval.log" | sed 's/; per condition:.*//')"
done
