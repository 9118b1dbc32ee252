"""What a sweep's tolerance costs and buys: one exploration grid (a single defect, eps x kappa,
the paper's standard chain) swept at several tolerances, timed, and compared with the same
grid at 1e-9. Prints a Markdown table (docs/python.md, "Which tolerance to explore at").

    .venv/bin/python python/benches/tolerance.py
"""

import time

import numpy as np

import woodpile

SCENE = {
    "defect": [{"site": 0, "eps": "$eps", "kappa": "$kappa"}],
    "run": {"t_end": 150.0, "tolerance": "$tol"},
}
AXES = {"eps": {"from": 0.1, "to": 100.0, "count": 12, "log": True},
        "kappa": {"from": 0.1, "to": 10.0, "count": 12, "log": True}}


def run(tol):
    started = time.perf_counter()
    frame = woodpile.sweep(SCENE, dict(AXES, tol=[tol]))
    return time.perf_counter() - started, frame


def main():
    _, reference = run(1e-9)
    print("| tolerance | seconds (144 scenes, both cores) | largest E_tr error against 1e-9 | largest error estimate |")
    print("|---|---|---|---|")
    for tol in (1e-5, 1e-6, 1e-7, 1e-8):
        seconds, frame = run(tol)
        error = np.max(np.abs(frame.E_tr.to_numpy() - reference.E_tr.to_numpy()))
        print(f"| {tol:.0e} | {seconds:.2f} | {error:.1e} | {frame.error_estimate.max():.1e} |")


if __name__ == "__main__":
    main()
