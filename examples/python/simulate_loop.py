"""Times `railforce.simulate` called 10 times in one process (the first call included) and
hashes every call's arrays, so two builds compare by time and by bytes.

Usage (from the repository root): python examples/python/simulate_loop.py LABEL
"""
import hashlib
import os
import sys
import time

import numpy as np
import railforce

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
t0 = time.perf_counter()
h = hashlib.sha256()
for i in range(10):
    cols = railforce.simulate(track=os.path.join(ROOT, "tracks/tangent.toml"), vehicle=os.path.join(ROOT, "vehicles/c80.toml"),
                              duration_s=1.0, settle_s=0.5, seed=1 + i % 2)
    for k in sorted(cols):
        h.update(k.encode()); h.update(np.ascontiguousarray(cols[k], dtype=np.float64).tobytes())
dt = time.perf_counter() - t0
print(f"{sys.argv[1]} {dt:.3f} s {h.hexdigest()[:16]}")
