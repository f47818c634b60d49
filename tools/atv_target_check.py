#!/usr/bin/env python3
"""Which of the ATV issue's calibration targets each run of `roamlab montecarlo --calibration-consistency` meets.

Reads DIR/calibrations/NNNNNN.json (error in the tangent space, reported std, truth) and prints per run and per target
whether the error is within the target and every component of it within 3 reported std; then per target how many runs
meet both. The targets: GPS lever-arm error norm <= 0.10 m, IMU misalignment angle <= 2 deg, every entry of the
magnetometer's A within 0.02 and of b within 0.01, kv/L and k_theta within 0.5 % of their truth, k_gamma within 0.005.

    tools/atv_target_check.py DIR
"""
import glob
import json
import math
import os
import sys

# name -> (what, error measure from the error vector and truth, limit)
TARGETS = {
    "gps.lever_arm": ("norm [m]", lambda e, t: math.sqrt(sum(x * x for x in e)), 0.10),
    "imu.misalignment": ("angle [deg]", lambda e, t: math.degrees(math.sqrt(sum(x * x for x in e))), 2.0),
    "magnetometer.A": ("max |entry|", lambda e, t: max(abs(x) for x in e), 0.02),
    "magnetometer.b": ("max |entry|", lambda e, t: max(abs(x) for x in e), 0.01),
    "odometer.kv_over_L": ("relative [%]", lambda e, t: 100 * abs(e[0] / t[0]), 0.5),
    "odometer.k_theta": ("relative [%]", lambda e, t: 100 * abs(e[0] / t[0]), 0.5),
    "odometer.k_gamma": ("|error| [rad]", lambda e, t: abs(e[0]), 0.005),
}


def main():
    if len(sys.argv) != 2 or sys.argv[1] in ("-h", "--help"):
        sys.exit(__doc__)
    files = sorted(glob.glob(os.path.join(sys.argv[1], "calibrations", "*.json")))
    if not files:
        sys.exit(sys.argv[1] + ": no calibrations/*.json")
    met = {name: 0 for name in TARGETS}
    calibrated = 0
    print("| run | " + " | ".join(TARGETS) + " |")
    print("|---" * (len(TARGETS) + 1) + "|")
    for path in files:
        run = json.load(open(path))
        if "failed" in run:  # a run that failed on its redrawn terrain (--redraw-terrain): no calibration to check
            print("| %d | failed: %s |" % (run["run"], run["failed"]))
            continue
        calibrated += 1
        cells = []
        for name, (_, measure, limit) in TARGETS.items():
            p = run["parameters"][name]
            value = measure(p["error"], p["truth"])
            sigmas = max(abs(e) / s for e, s in zip(p["error"], p["std"]))
            ok = value <= limit and sigmas <= 3.0
            met[name] += ok
            cells.append("%.3g, %.1f sd %s" % (value, sigmas, "ok" if ok else "NO"))
        print("| %d | %s |" % (run["run"], " | ".join(cells)))
    print()
    for name, (what, _, limit) in TARGETS.items():
        print("%-20s %-14s <= %-6g and within 3 std: %d of %d runs" % (name, what, limit, met[name], calibrated))


if __name__ == "__main__":
    main()
