#!/usr/bin/env python3
"""Which objective the OptiOdom twin's geometry fit needs, on the kinematic stand-in (tools/optiodom_drift_floor.py:
dead reckoning of the recorded encoder angles). A constant geometry (radius scale, right/left ratio, track error) is
fitted on the training runs' first two thirds (a further run too short to hold a window in its last third whole, as the
twin fits them) by Nelder-Mead on each of:
  increments: the chi-square of consecutive 10 s increments, each in the frame of the recorded heading at its start,
              along and across the recorded displacement d over sqrt(2) sigma and sqrt(2 sigma^2 + sigma_yaw^2 |d|^2);
  windows:    the chi-square of the drift's windows (gap/twin.h TwinResidualOptions): a 10 s window every second, the
              dead reckoning aligned over its first 2 s, the end error over sigma sqrt(1 + 1/n) along the lever from the
              aligned samples' centroid and with the alignment yaw's share across, each weighted sqrt(1 / 10);
  per run:    the same, each run's chi-square over its window count (every run weighs the same);
  drift:      the mean over the runs of each run's 10 s drift over its nominal drift (optiodom_drift_floor.py's fit, on
              the training parts);
and carried to the other runs named: each one's 10 s drift with the fitted geometry over its nominal drift.

    python3 tools/optiodom_fit_objectives.py DATA_DIR TRAINING_SET[,TRAINING_SET...] OTHER_SET...
      (DATA_DIR: the dataset's data/diff folder; a set as shape/name, e.g. square/231220200029)
"""
import bisect
import math
import pathlib
import sys

import optiodom_drift_floor as floor

WINDOW_S, STRIDE_S, ALIGN_S, TRAIN_FRACTION = 10.0, 1.0, 2.0, 2.0 / 3.0
SIGMA_M, SIGMA_YAW = floor.POSITION_SIGMA_M, floor.HEADING_SIGMA_RAD


def training_part(run, first):
    """The first two thirds, as the twin fits a run; a further run (not `first`) whose last third is too short for one
    window trains whole, as in the twin."""
    t = run["t"]
    if not first and (1.0 - TRAIN_FRACTION) * (t[-1] - t[0]) < 0.9 * WINDOW_S:
        return run
    n = max(2, int(TRAIN_FRACTION * len(t)))
    return {k: v[:n] for k, v in run.items()}


def windows(t, stride_s):
    """(start, end) sample pairs: a window every stride_s (None: consecutive), at least 0.9 of WINDOW_S long."""
    out, a = [], 0
    while True:
        b = a
        while b + 1 < len(t) and t[b + 1] - t[a] <= WINDOW_S + 1e-9:
            b += 1
        if b == a or t[b] - t[a] < 0.9 * WINDOW_S:
            return out
        out.append((a, b))
        a = b if stride_s is None else bisect.bisect_left(t, t[a] + stride_s - 1e-9)


def along_across(vector, direction):
    n = math.hypot(*direction)
    ux, uy = (direction[0] / n, direction[1] / n) if n > 0 else (1.0, 0.0)
    return vector[0] * ux + vector[1] * uy, -vector[0] * uy + vector[1] * ux, n


def increments(run, p):
    x, y, th = floor.dead_reckon(run, p)
    out = []
    for a, b in windows(run["t"], None):
        def increment(X, Y, heading):
            c, s = math.cos(-heading[a]), math.sin(-heading[a])
            dx, dy = X[b] - X[a], Y[b] - Y[a]
            return c * dx - s * dy, s * dx + c * dy
        recorded, reckoned = increment(run["x"], run["y"], run["th"]), increment(x, y, th)
        along, across, d = along_across((recorded[0] - reckoned[0], recorded[1] - reckoned[1]), recorded)
        out += [along / math.sqrt(2) / SIGMA_M, across / math.sqrt(2 * SIGMA_M**2 + SIGMA_YAW**2 * d * d)]
    return out


def drift_windows(run, p):
    t = run["t"]
    twin = floor.dead_reckon(run, p)
    weight, out = math.sqrt(STRIDE_S / WINDOW_S), []
    for a, b in windows(t, STRIDE_S):
        e = min(bisect.bisect_right(t, t[a] + ALIGN_S + 1e-9) - 1, b - 1)
        yaw, px, py = floor.alignment(run, twin, a, e)
        c, s = math.cos(yaw), math.sin(yaw)
        error = (run["x"][b] - (c * twin[0][b] - s * twin[1][b] + px), run["y"][b] - (s * twin[0][b] + c * twin[1][b] + py))
        n = e - a + 1
        cx, cy = sum(run["x"][a:e + 1]) / n, sum(run["y"][a:e + 1]) / n
        rho = sum((run["x"][i] - cx)**2 + (run["y"][i] - cy)**2 for i in range(a, e + 1))
        information = rho / SIGMA_M**2 + n / SIGMA_YAW**2
        along, across, lever = along_across(error, (run["x"][b] - cx, run["y"][b] - cy))
        point = SIGMA_M**2 * (1 + 1 / n)
        out += [weight * along / math.sqrt(point), weight * across / math.sqrt(point + lever**2 / information)]
    return out


def chi2(residuals):
    return sum(r * r for r in residuals)


def main(argv):
    if len(argv) < 3 or argv[1] in ("-h", "--help"):
        print(__doc__, file=sys.stderr if len(argv) < 3 else sys.stdout)
        return 0 if len(argv) > 1 and argv[1] in ("-h", "--help") else 2
    data = pathlib.Path(argv[1])
    training, others = argv[2].split(","), argv[3:]
    runs = {name: floor.load(data / name / f"{pathlib.Path(name).name}_run-01.csv") for name in training + others}
    parts = [training_part(runs[name], i == 0) for i, name in enumerate(training)]
    nominal = (1.0, 1.0, 0.0)
    nominal_drift = [floor.drift(part, nominal) for part in parts]
    objectives = {
        "increments": lambda p: sum(chi2(increments(part, p)) for part in parts),
        "windows": lambda p: sum(chi2(drift_windows(part, p)) for part in parts),
        "per run": lambda p: sum(chi2(r) / len(r) for r in (drift_windows(part, p) for part in parts)),
        "drift": lambda p: sum(floor.drift(part, p) / d for part, d in zip(parts, nominal_drift)),
    }
    print("| objective | scale, R/L, track | " + " | ".join(others) + " |")
    print("|---|---|" + "---|" * len(others))
    for label, objective in objectives.items():
        p = floor.nelder_mead(objective, nominal, (0.01, 0.003, 0.003), iterations=200)[0]
        ratios = [floor.drift(runs[name], p) / floor.drift(runs[name], nominal) for name in others]
        print(f"| {label} | {p[0]:.4f}, {p[1]:.4f}, {1000 * p[2]:+.2f} mm | " +
              " | ".join(f"{r:.2f}" for r in ratios) + " |", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
