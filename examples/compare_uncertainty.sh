#!/usr/bin/env bash
# One network, quantile heads and a 5-member ensemble, trained on the same data set with the
# same protocol, each timed and evaluated on the test seed: coverage of the 90 % interval and
# its mean width: which is better per unit of training time.
#   examples/compare_uncertainty.sh [DATA] [OUT]     (DATA: generate --plan demo --snr-db 6)
# Environment: SEED (first seed, default 1), CONFIGS (which of single, quantile-heads,
# ensemble5; default all three), TRAIN_ARGS (more `train` options, e.g. the experiments'
# `--epochs 100 --patience 10 --windows-per-epoch 50000 --val-windows 40000` at paper34 scale).
set -euo pipefail
R=${RAILFORCE:-target/release/railforce}
D=${1:-data/demo}
O=${2:-models/compare_uncertainty}
SEED=${SEED:-1}
CONFIGS=${CONFIGS:-single quantile-heads ensemble5}
mkdir -p "$O"
for name in $CONFIGS; do
  case $name in
    single) args="--no-quantile-heads" ;;
    quantile-heads) args="--quantile-heads 0.9" ;;
    ensemble5) args="--ensemble 5" ;;
    *) echo "unknown configuration $name (single, quantile-heads, ensemble5)" >&2; exit 2 ;;
  esac
  out="$O/${name}_seed$SEED"
  t0=$(date +%s.%N)
  # shellcheck disable=SC2086
  "$R" train --data "$D" --model cnn-bilstm --label centre --seed "$SEED" --out "$out" --force $args ${TRAIN_ARGS:-} > "$out.train.log" 2>&1
  t1=$(date +%s.%N)
  "$R" evaluate --model "$out" --data "$D" > "$out.eval.log" 2>&1
  printf '%s (seed %s): trained in %.0f s; pooled R² %s; %s\n' "$name" "$SEED" "$(echo "$t1 - $t0" | bc)" \
    "$(grep -E '^all \(pooled\)' "$out.eval.log" | awk '{printf "%s %s ", $3, $6}')" \
    "$(tail -1 "$out.eval.log" | sed 's/; per condition:.*//')"
done
