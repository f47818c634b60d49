#!/usr/bin/env python3
"""Where the block NEES of a calibration-consistency run comes from: the runs split by how much the driven wheels
slipped (an analysis tool: it reads the simulation's drive statistics, which the calibration never sees).

    python3 tools/consistency_by_slip.py OUT [--slip MPS]

OUT is the output directory of `roamlab montecarlo --calibration-consistency` (best with --redraw-terrain, where each
run drives its own terrain). Each run's file OUT/calibrations/NNNNNN.json holds `drive.max_wheel_slip_mps`, the largest
slip of a driven wheel's rim over the ground during the drive; OUT/consistency.json holds every block's NEES per run
(`per_run`, in the order of `calibrated_runs`). Printed: how many runs slipped more than MPS (default 0.3 m/s), then per
parameter the mean NEES over every run, over the runs that slipped more and over the others, the share of the NEES sum
the slipping runs hold, the Spearman rank correlation between a run's slip and its NEES, the median NEES, and the 95 %
band of the others' mean NEES (chi-square of n d degrees of freedom over n, by the Wilson-Hilferty approximation).
Standard library only.
"""
import argparse
import json
import math
import os
import sys


def load(out):
    with open(os.path.join(out, "consistency.json")) as f:
        summary = json.load(f)
    slip = {}
    for i in summary["calibrated_runs"]:
        with open(os.path.join(out, "calibrations", "%06d.json" % i)) as f:
            run = json.load(f)
        if "drive" not in run:
            sys.exit("%s: run %d has no drive statistics" % (out, i))
        slip[i] = run["drive"]["max_wheel_slip_mps"]
    return summary, slip


def ranks(values):
    order = sorted(range(len(values)), key=lambda k: values[k])
    r = [0.0] * len(values)
    k = 0
    while k < len(order):
        j = k
        while j + 1 < len(order) and values[order[j + 1]] == values[order[k]]:
            j += 1
        for m in range(k, j + 1):
            r[order[m]] = (k + j) / 2.0
        k = j + 1
    return r


def spearman(x, y):
    rx, ry = ranks(x), ranks(y)
    mx, my = sum(rx) / len(rx), sum(ry) / len(ry)
    sxy = sum((a - mx) * (b - my) for a, b in zip(rx, ry))
    sxx = sum((a - mx) ** 2 for a in rx)
    syy = sum((b - my) ** 2 for b in ry)
    return sxy / math.sqrt(sxx * syy) if sxx > 0 and syy > 0 else float("nan")


def average_nees_band(n, d):
    """95 % band of the mean of n NEES of d degrees of freedom (Wilson-Hilferty, within 1 % of the exact quantiles)."""
    k = n * d
    h = 2.0 / (9.0 * k)
    return tuple(d * (1.0 - h + z * math.sqrt(h)) ** 3 for z in (-1.959964, 1.959964))


def mean(values):
    return sum(values) / len(values) if values else float("nan")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("out")
    parser.add_argument("--slip", type=float, default=0.3, help="slip threshold [m/s] (0.3)")
    args = parser.parse_args()
    summary, slip = load(args.out)
    runs = summary["calibrated_runs"]
    slipping = [slip[i] > args.slip for i in runs]
    failed = summary.get("failed_runs", [])
    print("%d calibrated runs (%d failed); %d slipped more than %.2f m/s (max wheel slip: median %.3f, max %.3f m/s)"
          % (len(runs), len(failed), sum(slipping), args.slip, sorted(slip.values())[len(slip) // 2],
             max(slip.values())))
    print("%-20s %5s %10s %10s %10s %16s %10s %9s %8s" % ("parameter", "dim", "NEES all", "slipping", "others",
                                                          "others' band", "share [%]", "Spearman", "median"))
    for block in summary["parameters"]:
        nees = block["nees"]["per_run"]
        pairs = [(s, n, slip[i]) for s, n, i in zip(slipping, nees, runs) if n is not None]
        high = [n for s, n, _ in pairs if s]
        low = [n for s, n, _ in pairs if not s]
        total = sum(n for _, n, _ in pairs)
        share = 100.0 * sum(high) / total if total > 0 else float("nan")
        rho = spearman([x for _, _, x in pairs], [n for _, n, _ in pairs])
        band = average_nees_band(len(low), block["dimension"]) if low else (float("nan"), float("nan"))
        values = sorted(n for _, n, _ in pairs)
        median = values[len(values) // 2] if len(values) % 2 else 0.5 * sum(values[len(values) // 2 - 1:][:2])
        print("%-20s %5d %10.2f %10.2f %10.2f   [%5.2f, %5.2f] %10.0f %9.2f %8.2f"
              % (block["name"], block["dimension"], mean([n for _, n, _ in pairs]), mean(high), mean(low), band[0],
                 band[1], share, rho, median))


if __name__ == "__main__":
    main()
