"""Baseline for woodpile's speed claims: the standard scene by classical RK4, numba-compiled.

The same scene and arithmetic as rk4_chain.c (sites -100..100, fixed walls, eps = 10, kappa = 1
at site 0, impulse at -25, t in [0, 150]). Usage: python3 rk4_numba.py [dt] [repeats]; prints
one JSON line with E_tr and the best wall time in ms (after a warm-up call that compiles).
"""
import json
import math
import sys
import time

import numpy as np
from numba import njit

S = 201
N = S + 1
DEFECT = 100
STRIKER = 75
EPS = 10.0
KAPPA = 1.0


@njit(cache=False, fastmath=False)
def accel(q, a):
    a[:] = 0.0
    for b in range(S - 1):
        d = q[b] - q[b + 1]
        if d > 0.0:
            f = d * math.sqrt(d)
            a[b] -= f
            a[b + 1] += f
    if -q[0] > 0.0:
        a[0] += (-q[0]) * math.sqrt(-q[0])
    if q[S - 1] > 0.0:
        a[S - 1] -= q[S - 1] * math.sqrt(q[S - 1])
    f = KAPPA * (q[DEFECT] - q[S])
    a[DEFECT] -= f
    a[S] = f / EPS


@njit(cache=False)
def run(dt, t_end):
    q = np.zeros(N)
    v = np.zeros(N)
    v[STRIKER] = 1.0
    qs = np.zeros(N)
    a1 = np.zeros(N); a2 = np.zeros(N); a3 = np.zeros(N); a4 = np.zeros(N)
    v2 = np.zeros(N); v3 = np.zeros(N); v4 = np.zeros(N)
    steps = int(math.ceil(t_end / dt - 1e-9))
    h = t_end / steps
    for _ in range(steps):
        accel(q, a1)
        for i in range(N):
            qs[i] = q[i] + 0.5 * h * v[i]
            v2[i] = v[i] + 0.5 * h * a1[i]
        accel(qs, a2)
        for i in range(N):
            qs[i] = q[i] + 0.5 * h * v2[i]
            v3[i] = v[i] + 0.5 * h * a2[i]
        accel(qs, a3)
        for i in range(N):
            qs[i] = q[i] + h * v3[i]
            v4[i] = v[i] + h * a3[i]
        accel(qs, a4)
        for i in range(N):
            q[i] += h / 6.0 * (v[i] + 2.0 * v2[i] + 2.0 * v3[i] + v4[i])
            v[i] += h / 6.0 * (a1[i] + 2.0 * a2[i] + 2.0 * a3[i] + a4[i])
    e = np.zeros(S)
    for n in range(S):
        e[n] = 0.5 * v[n] * v[n]
    for b in range(S - 1):
        d = q[b] - q[b + 1]
        if d > 0.0:
            p = 0.4 * d * d * math.sqrt(d)
            e[b] += 0.5 * p
            e[b + 1] += 0.5 * p
    if -q[0] > 0.0:
        e[0] += 0.4 * (-q[0]) ** 2.5
    if q[S - 1] > 0.0:
        e[S - 1] += 0.4 * q[S - 1] ** 2.5
    x = q[DEFECT] - q[S]
    e[DEFECT] += 0.5 * EPS * v[S] * v[S] + 0.5 * KAPPA * x * x
    return (e[DEFECT - 1] + e[DEFECT] + e[DEFECT + 1]) / e.sum()


def main():
    dt = float(sys.argv[1]) if len(sys.argv) > 1 else 0.01
    repeats = int(sys.argv[2]) if len(sys.argv) > 2 else 10
    run(dt, 1.0)  # compile
    best, e_tr = math.inf, 0.0
    for _ in range(repeats):
        t0 = time.perf_counter()
        e_tr = run(dt, 150.0)
        best = min(best, (time.perf_counter() - t0) * 1e3)
    print(json.dumps({"implementation": "numba RK4", "dt": dt, "E_tr": e_tr, "ms": round(best, 3)}))


if __name__ == "__main__":
    main()
