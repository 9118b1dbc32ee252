"""Baseline for woodpile's speed claims: the standard scene by classical RK4, numba-compiled.

The same scene and arithmetic as rk4_chain.c (sites -100..100, fixed walls, eps = 10, kappa = 1
at site 0, impulse at -25, t in [0, 150]), integrated by the RK4 of rk4_numba_scenes.py (the
paper-level baseline), so that both baselines are one piece of code. Usage:
python3 rk4_numba.py [dt] [repeats]; prints one JSON line with E_tr and the best wall time in ms
(after a warm-up call that compiles).
"""
import json
import math
import sys
import time

from rk4_numba_scenes import arguments, run

STANDARD = {
    "n": 201, "fixed": True, "striker": 75, "velocity": 1.0, "t_end": 150.0,
    "lo": 99, "hi": 101, "res": [[100, 10.0, 1.0]],
}


def main():
    dt = float(sys.argv[1]) if len(sys.argv) > 1 else 0.01
    repeats = int(sys.argv[2]) if len(sys.argv) > 2 else 10
    run(*arguments(dict(STANDARD, dt=dt, t_end=1.0)))  # compile
    args = arguments(dict(STANDARD, dt=dt))
    best, e_tr = math.inf, 0.0
    for _ in range(repeats):
        t0 = time.perf_counter()
        e_tr = run(*args)[2]
        best = min(best, (time.perf_counter() - t0) * 1e3)
    print(json.dumps({"implementation": "numba RK4", "dt": dt, "E_tr": e_tr, "ms": round(best, 3)}))


if __name__ == "__main__":
    main()
