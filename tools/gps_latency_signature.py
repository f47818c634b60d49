#!/usr/bin/env python3
"""How much a GPS latency shows beside a free lever arm, per part of a simulated drive: an analysis tool (it reads the
truth; `roamlab diagnose` never does).

    python3 tools/gps_latency_signature.py REC [--windows 1-20,21-29]

REC is a simulated recording (ground_truth.tum, gps.csv, recording.yaml, truth.yaml with `gps.lever_arm` and a
`gps_latency` effect). A fix stamped t is the antenna at t - latency. Without the latency in the model, a self-
calibrated lever arm absorbs most of it (the mean speed times the latency, along the body's x); what is left is the
signature the data can hold against the lever arm. Per window, on the true poses:
  - signature: chi2 (in units of the fixes' sigma) between the fixes the true model predicts without noise and those of
    the least-squares lever arm without latency: the held-out chi2 drop a latency candidate can expect there;
  - recorded: chi2 of the recorded fixes against the true model, and against that best lever arm without latency
    (their difference is the drop this noise draw gives).
The fixes' sigma is read from recording.yaml (the gps stream's sigma_m). Standard library only.
"""
import argparse
import csv
import math
import os
import re

WGS84_A = 6378137.0
WGS84_F = 1.0 / 298.257223563
WGS84_E2 = WGS84_F * (2.0 - WGS84_F)


def ecef(lat_deg, lon_deg, h):
    lat, lon = math.radians(lat_deg), math.radians(lon_deg)
    n = WGS84_A / math.sqrt(1.0 - WGS84_E2 * math.sin(lat) ** 2)
    return ((n + h) * math.cos(lat) * math.cos(lon), (n + h) * math.cos(lat) * math.sin(lon),
            (n * (1.0 - WGS84_E2) + h) * math.sin(lat))


class Enu:
    def __init__(self, lat_deg, lon_deg, h):
        self.origin = ecef(lat_deg, lon_deg, h)
        self.lat, self.lon = math.radians(lat_deg), math.radians(lon_deg)

    def __call__(self, lat_deg, lon_deg, h):
        x = [p - q for p, q in zip(ecef(lat_deg, lon_deg, h), self.origin)]
        sl, cl, so, co = math.sin(self.lat), math.cos(self.lat), math.sin(self.lon), math.cos(self.lon)
        return (-so * x[0] + co * x[1], -sl * co * x[0] - sl * so * x[1] + cl * x[2],
                cl * co * x[0] + cl * so * x[1] + sl * x[2])


def rotate(q, v):
    """q = (x, y, z, w), world from body."""
    x, y, z, w = q
    r = [[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
         [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
         [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]]
    return [sum(r[i][j] * v[j] for j in range(3)) for i in range(3)]


def numbers(text):
    return [float(s) for s in re.findall(r"-?\d+(?:\.\d+)?(?:e-?\d+)?", text)]


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("recording")
    parser.add_argument("--windows", default="1-20,21-29", help="time windows [s], e.g. 1-20,21-29")
    args = parser.parse_args()
    rec = args.recording

    meta = open(os.path.join(rec, "recording.yaml")).read()
    origin = re.search(r"origin:\s*\{latitude_deg:\s*([-\d.e]+),\s*longitude_deg:\s*([-\d.e]+),\s*altitude_m:\s*"
                       r"([-\d.e]+)\}", meta)
    sigma = re.search(r"name:\s*gps\b.*?sigma_m:\s*([-\d.e]+)", meta, re.S)
    truth = open(os.path.join(rec, "truth.yaml")).read()
    lever_line = re.search(r"gps\.lever_arm:\s*\[([^\]]*)\]", truth)
    latency_line = re.search(r"gps_latency\s*\n\s*parameters:\s*\{latency_s:\s*([-\d.e]+)\}", truth)
    if not (origin and sigma and lever_line and latency_line):
        raise SystemExit(f"{rec}: needs recording.yaml's origin and gps sigma_m, truth.yaml's gps.lever_arm and a "
                         "gps_latency effect")
    enu = Enu(*map(float, origin.groups()))
    sigma_m = float(sigma.group(1))
    lever = numbers(lever_line.group(1))
    latency = float(latency_line.group(1))

    poses = {}
    for line in open(os.path.join(rec, "ground_truth.tum")):
        if line.startswith("#") or not line.strip():
            continue
        r = [float(v) for v in line.split()]
        poses[round(r[0] * 1000)] = r[1:]
    period_ms = min(b - a for a, b in zip(sorted(poses), sorted(poses)[1:]))

    def pose_at(t):
        return poses[round(t * 1000 / period_ms) * period_ms]

    def predicted(t, lever_body, tau):
        p = pose_at(t - tau)
        o = rotate(p[3:], lever_body)
        return [p[i] + o[i] for i in range(3)]

    def best_lever(stamps, target):
        """Least-squares body-frame lever arm, no latency: the mean of R^T (fix - position)."""
        s = [0.0, 0.0, 0.0]
        for t, z in zip(stamps, target):
            p = pose_at(t)
            d = rotate((-p[3], -p[4], -p[5], p[6]), [z[i] - p[i] for i in range(3)])
            s = [s[i] + d[i] for i in range(3)]
        return [v / len(stamps) for v in s]

    def chi2(stamps, target, lever_body, tau):
        return sum(sum((z[i] - predicted(t, lever_body, tau)[i]) ** 2 for i in range(3))
                   for t, z in zip(stamps, target)) / sigma_m ** 2

    fixes = []
    with open(os.path.join(rec, "gps.csv")) as f:
        for row in csv.reader(f):
            if row and row[0][:1].isdigit():
                fixes.append((float(row[0]), enu(float(row[1]), float(row[2]), float(row[3]))))
    first = min(poses) / 1000.0 + latency
    print(f"{rec}: latency {latency} s, lever arm {lever} m, fixes sigma {sigma_m} m")
    print("window [s] | fixes | signature chi2 | recorded: true model, best lever arm without latency (lever arm)")
    for window in args.windows.split(","):
        t0, t1 = (float(v) for v in window.split("-"))
        stamps = [t for t, _ in fixes if t0 <= t <= t1 and t >= first]
        recorded = [z for t, z in fixes if t0 <= t <= t1 and t >= first]
        ideal = [predicted(t, lever, latency) for t in stamps]
        signature = chi2(stamps, ideal, best_lever(stamps, ideal), 0.0)
        fitted = best_lever(stamps, recorded)
        print(f"{t0:g}-{t1:g} | {len(stamps)} | {signature:.1f} | {chi2(stamps, recorded, lever, latency):.1f}, "
              f"{chi2(stamps, recorded, fitted, 0.0):.1f} ({', '.join(f'{v:.2f}' for v in fitted)})")


if __name__ == "__main__":
    main()
