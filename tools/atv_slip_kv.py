#!/usr/bin/env python3
"""What the rear tires' longitudinal slip does to the ATV's calibrated kv/L: an analysis tool (it reads the truth; the
estimator never does).

    python3 tools/atv_slip_kv.py [--roamlab build/apps/roamlab] [--scenario scenarios/atv_hills.yaml]
                                 [--config configs/atv_calibration.yaml] [--seed 1] [--slip-s 0.00167]
                                 [--front-drag-share 0]

A driven tire turns faster than the ground passes by a slip velocity s = c f_x / m that grows with its traction f_x
(measured on the physics: RollingRadiusTest.TheAtvsRearTiresSlipAtAVelocityProportionalToTheTraction prints c). Over
the level drive that defines truth.yaml's kv/L the tires carry only the rolling resistance, so on the scenario's drive
the slip beyond it is c times the traction per unit mass beyond the resistance's, which is O's forward specific force
f_x = a_x + g sin(pitch), the estimator's own slip regressor (the resistance's change with speed aside). In a turn
the rear tires also push against the steered front tires' side force, whose component along O's x is about the front
axle's share of m a_y times tan(delta); --front-drag-share S adds S a_y tan(delta) to f_x (a_y = v_x omega_z, delta
the true bicycle angle from the noise-free steering reading and truth.yaml's k_theta and k_gamma) as a rough estimate
of it (0.44: the static share of the ATV's weight on the front axle). The contacts' own traction lies between the two
(RollingRadiusTest.TheWeavesRearTractionLiesBetweenTheSpecificForceAndItsFrontDragEstimate prints its speed-weighted
mean beside theirs).

Simulates the scenario with every sensor noise set to zero (tools/atv_odometer_residuals.py's way), takes f_x from the
ground-truth poses of O (the second difference of the positions at each rear-wheel reading's interval, plus gravity,
in O at the interval's middle) and writes a copy of the recording whose rear-wheel readings have the slip c f_x taken
out (through truth.yaml's kv/L: the reading is the wheel's rolling speed over kv/L L). Calibrates both with the
configuration and prints their kv/L against truth.yaml's, the difference (what the slip does to the calibrated kv/L),
and the first-order shift the speed row alone predicts, -c <v f_x> / <v^2> (v O's forward speed). Standard library
only.
"""
import argparse
import csv
import json
import math
import os
import re
import shutil
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from atv_odometer_residuals import qconj, qexp, qlog, qmul, rotate, simulate_noiseless  # noqa: E402

GRAVITY_MPS2 = 9.80665


def read_poses(rec):
    poses = []
    for line in open(os.path.join(rec, "ground_truth.tum")):
        if line.strip() and not line.startswith("#"):
            f = [float(x) for x in line.split()]
            poses.append((f[0], f[1:4], (f[7], f[4], f[5], f[6])))
    return poses


def forward_motion(poses):
    """Per pose interval [t_k, t_k+1], keyed by round(t_k in ms): O's forward speed, forward specific force and yaw
    rate, in O at the interval's middle (the speed from the interval's chord, the acceleration from the chords of the
    intervals before and after)."""
    chords = []
    for (t0, p0, q0), (t1, p1, q1) in zip(poses, poses[1:]):
        dt = t1 - t0
        q_mid = qmul(q0, qexp([c / 2 for c in qlog(qmul(qconj(q0), q1))]))
        chords.append((t0, dt, q_mid, [(b - a) / dt for a, b in zip(p0, p1)], qlog(qmul(qconj(q0), q1))[2] / dt))
    motion = {}
    for before, (t0, dt, q_mid, v_world, omega_z), after in zip(chords, chords[1:], chords[2:]):
        a_world = [(c - a) / (after[0] - before[0]) for a, c in zip(before[3], after[3])]
        a_world[2] += GRAVITY_MPS2
        motion[round(t0 * 1e3)] = (rotate(qconj(q_mid), v_world)[0], rotate(qconj(q_mid), a_world)[0], omega_z)
    return motion


def calibrate(roamlab, rec, config, out):
    subprocess.run([roamlab, "calibrate", rec, "--config", config, "--out", out, "--quiet"], check=True,
                   stdout=subprocess.DEVNULL)
    estimate = json.load(open(os.path.join(out, "calibration.json")))["parameters"]["odometer.kv_over_L"]
    return estimate["estimate"][0], estimate["std"][0]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--roamlab", default="build/apps/roamlab")
    ap.add_argument("--scenario", default="scenarios/atv_hills.yaml")
    ap.add_argument("--config", default="configs/atv_calibration.yaml")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--slip-s", type=float, default=0.00167, help="slip velocity per m/s^2 of traction per mass [s]")
    ap.add_argument("--front-drag-share", type=float, default=0.0,
                    help="add this share of m a_y tan(delta) to the traction (the front tires' drag in turns)")
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        rec = simulate_noiseless(args.roamlab, args.scenario, args.seed, tmp)
        truth = open(os.path.join(rec, "truth.yaml")).read()
        kv_true = float(re.search(r"odometer.kv_over_L: *([0-9.eE+-]+)", truth).group(1))
        wheelbase = float(re.search(r"wheelbase_m: *([0-9.eE+-]+)",
                                    open(os.path.join(rec, "recording.yaml")).read()).group(1))
        k_theta = float(re.search(r"odometer.k_theta: *([0-9.eE+-]+)", truth).group(1))
        k_gamma = float(re.search(r"odometer.k_gamma: *([0-9.eE+-]+)", truth).group(1))
        steering = {round(float(r[0]) * 1e3): (float(r[1]) - k_gamma) / k_theta
                    for r in list(csv.reader(open(os.path.join(rec, "steering.csv"))))[1:]}
        motion = forward_motion(read_poses(rec))

        # The copy without the slip: each reading less c f_x over kv/L L (readings without both neighbours kept).
        slipless = os.path.join(tmp, "slipless")
        shutil.copytree(rec, slipless)
        rows = list(csv.reader(open(os.path.join(rec, "rear_wheel.csv"))))
        speeds, forces, corrected = [], [], 0
        for row in rows[1:]:
            key = round(float(row[0]) * 1e3)
            if key not in motion or key not in steering:
                continue
            v_x, f_x, omega_z = motion[key]
            f_x += args.front_drag_share * v_x * omega_z * math.tan(steering[key])
            row[1] = repr(float(row[1]) - args.slip_s * f_x / (kv_true * wheelbase))
            speeds.append(v_x)
            forces.append(f_x)
            corrected += 1
        with open(os.path.join(slipless, "rear_wheel.csv"), "w", newline="") as f:
            csv.writer(f, lineterminator="\n").writerows(rows)

        kv_slip, std = calibrate(args.roamlab, rec, args.config, os.path.join(tmp, "cal_slip"))
        kv_free, _ = calibrate(args.roamlab, slipless, args.config, os.path.join(tmp, "cal_slipless"))
    mean_vf = sum(v * f for v, f in zip(speeds, forces)) / len(speeds)
    mean_vv = sum(v * v for v in speeds) / len(speeds)
    mean_f = sum(forces) / len(forces)
    print("%d of %d rear-wheel readings corrected by c f_x, c = %.5f s, front drag share %.2f; f_x mean %+.4f m/s^2, rms %.4f m/s^2, "
          "<v f_x> %+.4f m^2/s^3, <v^2> %.3f m^2/s^2" %
          (corrected, len(rows) - 1, args.slip_s, args.front_drag_share, mean_f, math.sqrt(sum(f * f for f in forces) / len(forces)),
           mean_vf, mean_vv))
    print("truth.yaml's kv/L %.6f; noise-free calibration (std %.6f):" % (kv_true, std))
    print("  with the slip (the recording)  %.6f  %+.4f %%" % (kv_slip, 100 * (kv_slip / kv_true - 1)))
    print("  without it                     %.6f  %+.4f %%" % (kv_free, 100 * (kv_free / kv_true - 1)))
    print("  the slip's shift of kv/L       %+.4f %% (the speed row alone, -c <v f_x> / <v^2>: %+.4f %%)" %
          (100 * (kv_slip - kv_free) / kv_true, -100 * args.slip_s * mean_vf / mean_vv))


if __name__ == "__main__":
    main()
