"""Replays `auto`'s verification ladder offline on the fractions that the `ladder_data` example
records, for several companion ratios, and reports misses (true error above the tolerance),
the worst error / tolerance and the force evaluations: a cheap way to try a ladder design
before changing `run.rs`.

    cargo run --release -p woodpile-bench --example ladder_data > ladder.csv
    python3 scripts/auto_ladder_offline.py ladder.csv

The recorded steps form a geometric ladder of ratio 0.85, so a companion k rungs up has ratio
0.85^-k (k = 4: 1.92, close to auto's 2). The first step follows `Plan::dt_for` (error model,
omega * dt <= 0.5, 0.9 of the stability bound, at most 0.25), snapped to the nearest rung; the
estimate is Richardson's |F(coarse) - F(fine)| / (r^q - 1), accepted at half the tolerance.
Nonlinear resonators' energy cap is not modelled.
"""
import csv
import math
import re
import sys
from collections import defaultdict

MODEL = {"rk4c": (1.56e-2, 3.0, 2.828), "rkn4c": (5.2e-3, 2.8, 2.586)}


def load(path):
    runs = defaultdict(list)
    refs, labels = {}, {}
    with open(path) as f:
        for row in csv.DictReader(f):
            scene = int(row["scene"])
            labels[scene] = row["label"]
            values = tuple(float(row[k]) for k in ("R", "T", "E_tr"))
            if row["method"] == "ref":
                refs[scene] = values
            else:
                runs[(scene, row["method"])].append((float(row["dt"]), values, int(row["evals"])))
    for key in runs:
        runs[key].sort(key=lambda r: -r[0])
    return runs, refs, labels


def largest_omega(label):
    eps = [float(x) for x in re.findall(r"eps=([\d.]+)", label)]
    eps += [float(x) for x in re.findall(r"\(([\d.]+), ([\d.]+)\)", label)[0]] if "F7" in label else []
    return max(math.sqrt(1 + 1 / e) for e in eps)


def first_step(method, label, tol):
    coef, order, stability = MODEL[method]
    omega = largest_omega(label)
    return min((tol / coef) ** (1 / order), 0.5 / omega, 0.9 * stability / omega, 0.25)


def largest_difference(a, b):
    """The largest difference in R, T or E_tr (`Fractions::largest_difference`)."""
    return max(abs(x - y) for x, y in zip(a, b))


def replay(ladder, reference, method, label, tol, rungs, min_ratio=0.0, advance=None, shift=0):
    """`advance`: rungs between successive fine runs (default `rungs`, auto's halving);
    `shift`: rungs to start above the snapped first step (a larger first step)."""
    advance = advance or rungs
    dts = [r[0] for r in ladder]
    h = first_step(method, label, tol)
    i = min(range(len(dts)), key=lambda k: abs(math.log(dts[k] / h))) - shift
    used = set()

    def fractions(k):
        if k < 0 or k >= len(ladder):
            return None
        used.add(k)
        f = ladder[k][1]
        return None if any(math.isnan(x) for x in f) else f

    order = MODEL[method][1]
    while i < len(ladder):
        fine, coarse = fractions(i), fractions(i - rungs)
        if fine is not None and coarse is not None:
            r = dts[i - rungs] / dts[i]
            change = largest_difference(coarse, fine)
            estimate = change / (r**order - 1)
            # As `auto`'s asymptotic check: with a coarser run already made by the ladder, the
            # changes must shrink by at least `min_ratio` per rung pair (a plateau of equal
            # errors otherwise passes), unless the last change is itself within half the
            # tolerance.
            coarser = fractions(i - 2 * rungs) if (i - 2 * rungs) in used else None
            shrinks = (
                coarser is None
                or change <= 0.5 * tol
                or largest_difference(coarser, coarse) >= min_ratio * change
            )
            if estimate <= 0.5 * tol and shrinks:
                error = largest_difference(fine, reference)
                return error / tol, sum(ladder[k][2] for k in used)
        i += advance
    return None, sum(ladder[k][2] for k in used)


def summary(results):
    """Scenes, not converged, missed, worst error / tolerance, evaluations."""
    ratios = [r for r, _ in results if r is not None]
    return (
        f"{len(results)} {sum(r is None for r, _ in results)} {sum(r > 1 for r in ratios)}"
        f" {max(ratios):.2f} {sum(e for _, e in results)}"
    )


def main():
    runs, refs, labels = load(sys.argv[1] if len(sys.argv) > 1 else "ladder.csv")
    print("method rungs ratio min_shrink tolerance scenes not_converged missed worst_err/tol evals")
    for method in MODEL:
        for rungs, min_ratio in ((2, 0), (3, 0), (4, 0), (4, 2), (4, 3), (4, 4)):
            for tol in (1e-5, 1e-6, 1e-7):
                results = [
                    replay(runs[(s, method)], refs[s], method, labels[s], tol, rungs, min_ratio)
                    for s in labels
                ]
                print(f"{method} {rungs} {0.85 ** -rungs:.2f} {min_ratio} {tol:.0e} {summary(results)}")
    # Other ladder shapes for auto's method, with its asymptotic check (shrink by 2^(q-1)):
    # as auto (companion ~1.92x, halving), a first step 1.38x larger, and fine runs 1.38x
    # apart each paired with the run ~1.92x coarser.
    method = "rk4c"
    shrink = 2 ** (MODEL[method][1] - 1)
    print("ladder shape (rk4c) tolerance scenes not_converged missed worst_err/tol evals")
    for shape, advance, shift in (("auto", 4, 0), ("first_step_x1.38", 4, 2), ("advance_x1.38", 2, 0)):
        for tol in (1e-5, 1e-6, 1e-7, 1e-8):
            results = [
                replay(runs[(s, method)], refs[s], method, labels[s], tol, 4, shrink, advance, shift)
                for s in labels
            ]
            print(f"{shape} {tol:.0e} {summary(results)}")


if __name__ == "__main__":
    main()
