"""Baseline for woodpile's paper-level speed claim: many scenes of the paper's sweeps by
classical RK4 at a fixed step on the full chain, numba-compiled, as a researcher would script
them.

Reads a JSON list of scenes on stdin, each
  {"n": sites, "fixed": true, "striker": index, "velocity": v, "t_end": t, "dt": dt,
   "lo": first site of the region, "hi": last site, "res": [[site, eps, kappa, p], ...]}
(resonators with the coupling force kappa (u - w)^p, p odd, 1 when left out; sites as 0-based
indices) and an optional count of repeats (argument, 3 by
default), and prints one JSON line: the fractions R, T,
E_tr of every scene (normalised by the total energy at t_end, each site carrying its kinetic
energy, half of each contact's potential, all of a wall contact's, and its resonator's energy:
woodpile's convention), and the summed wall time in ms over the sample, the best of the repeats
and the first pass's (`first_ms`), after a warm-up call that compiles.
One thread.

rk4_numba.py is the same RK4 for the standard scene alone, with its constants compiled in: it
stays a separate script because that makes it about 5% faster than this general one on the
same scene (19.6 against 20.4 to 21.2 ms), and a baseline should be the fastest plain script.
"""
import json
import math
import sys
import time

import numpy as np
from numba import njit


@njit(cache=False, fastmath=False)
def accel(q, a, n, fixed, rs, re, rk, rp):
    a[:] = 0.0
    for b in range(n - 1):
        d = q[b] - q[b + 1]
        if d > 0.0:
            f = d * math.sqrt(d)
            a[b] -= f
            a[b + 1] += f
    if fixed:
        if -q[0] > 0.0:
            a[0] += (-q[0]) * math.sqrt(-q[0])
        if q[n - 1] > 0.0:
            a[n - 1] -= q[n - 1] * math.sqrt(q[n - 1])
    for j in range(rs.shape[0]):
        d = q[rs[j]] - q[n + j]
        f = rk[j] * d if rp[j] == 1 else rk[j] * d ** rp[j]
        a[rs[j]] -= f
        a[n + j] = f / re[j]


@njit(cache=False)
def run(n, fixed, striker, velocity, t_end, dt, rs, re, rk, rp, lo, hi):
    m = n + rs.shape[0]
    q = np.zeros(m)
    v = np.zeros(m)
    v[striker] = velocity
    qs = np.zeros(m)
    a1 = np.zeros(m); a2 = np.zeros(m); a3 = np.zeros(m); a4 = np.zeros(m)
    v2 = np.zeros(m); v3 = np.zeros(m); v4 = np.zeros(m)
    steps = int(math.ceil(t_end / dt - 1e-9))
    h = t_end / steps
    for _ in range(steps):
        accel(q, a1, n, fixed, rs, re, rk, rp)
        for i in range(m):
            qs[i] = q[i] + 0.5 * h * v[i]
            v2[i] = v[i] + 0.5 * h * a1[i]
        accel(qs, a2, n, fixed, rs, re, rk, rp)
        for i in range(m):
            qs[i] = q[i] + 0.5 * h * v2[i]
            v3[i] = v[i] + 0.5 * h * a2[i]
        accel(qs, a3, n, fixed, rs, re, rk, rp)
        for i in range(m):
            qs[i] = q[i] + h * v3[i]
            v4[i] = v[i] + h * a3[i]
        accel(qs, a4, n, fixed, rs, re, rk, rp)
        for i in range(m):
            q[i] += h / 6.0 * (v[i] + 2.0 * v2[i] + 2.0 * v3[i] + v4[i])
            v[i] += h / 6.0 * (a1[i] + 2.0 * a2[i] + 2.0 * a3[i] + a4[i])
    e = np.zeros(n)
    for s in range(n):
        e[s] = 0.5 * v[s] * v[s]
    for b in range(n - 1):
        d = q[b] - q[b + 1]
        if d > 0.0:
            p = 0.4 * d * d * math.sqrt(d)
            e[b] += 0.5 * p
            e[b + 1] += 0.5 * p
    if fixed:
        if -q[0] > 0.0:
            e[0] += 0.4 * (-q[0]) ** 2.5
        if q[n - 1] > 0.0:
            e[n - 1] += 0.4 * q[n - 1] ** 2.5
    for j in range(rs.shape[0]):
        x = q[rs[j]] - q[n + j]
        e[rs[j]] += 0.5 * re[j] * v[n + j] * v[n + j] + rk[j] * x ** (rp[j] + 1) / (rp[j] + 1)
    total = e.sum()
    return e[:lo].sum() / total, e[hi + 1:].sum() / total, e[lo:hi + 1].sum() / total


def arguments(scene):
    res = scene["res"]
    return (
        scene["n"], scene["fixed"], scene["striker"], scene["velocity"], scene["t_end"],
        scene["dt"],
        np.array([r[0] for r in res], dtype=np.int64),
        np.array([r[1] for r in res], dtype=np.float64),
        np.array([r[2] for r in res], dtype=np.float64),
        np.array([r[3] if len(r) > 3 else 1 for r in res], dtype=np.int64),
        scene["lo"], scene["hi"],
    )


def main():
    repeats = int(sys.argv[1]) if len(sys.argv) > 1 else 3
    scenes = [arguments(scene) for scene in json.load(sys.stdin)]
    warm = list(scenes[0])
    warm[4] = 1.0  # t_end
    run(*warm)  # compile
    best_ms, first_ms, out = math.inf, None, []
    for _ in range(repeats):
        out, total_ms = [], 0.0
        for args in scenes:
            t0 = time.perf_counter()
            r, t, e_tr = run(*args)
            total_ms += (time.perf_counter() - t0) * 1e3
            out.append({"R": r, "T": t, "E_tr": e_tr})
        best_ms = min(best_ms, total_ms)
        first_ms = total_ms if first_ms is None else first_ms
    print(json.dumps({"implementation": "numba RK4", "fractions": out, "ms": round(best_ms, 3),
                      "first_ms": round(first_ms, 3)}))


if __name__ == "__main__":
    main()
