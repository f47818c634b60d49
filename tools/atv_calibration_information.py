#!/usr/bin/env python3
"""How much the ATV's 30 s drives can tell the calibration: an analysis tool (it reads the truth; the estimator never
does).

    python3 tools/atv_calibration_information.py [--roamlab build/apps/roamlab] [--scenario scenarios/atv_hills.yaml]
        [--config configs/atv_calibration.yaml] [--drives NAME,...] [--noisy DRIVE [--seeds 1,2,3]]
        [--sweep DRIVE [--terrain-seeds 7,...,16] [--reliefs 4,5]] [--keep DIR]

For each drive (a variant of the scenario: terrain seed and relief, speed and handlebar profiles; DRIVES below) it
simulates the scenario with every sensor noise set to zero and calibrates that recording with the configuration: on a
recording without noise the solution sits at the truth (up to the physics the configuration does not model) and the
standard deviation `calibrate` reports is the Cramer-Rao bound of the configured noise. Printed per drive: the drive's
tilt (roll and pitch of O: RMS about the mean and range), heading span, peak lateral acceleration v omega_z (0.2 s
means), the largest side slip simulate reports, and the reported std of every Table I target next to the target
(k_theta also with its error without noise: a bias of the physics the configuration does not model); then two bounds
with the true trajectory known up to an offset (linear least squares, no dead-reckoning error): the GPS lever arm's
height from sigma_GPS and the tilts at the fixes, and the magnetometer's b from sigma_MAG and the spread of the field in
the IMU frame (b and A's column on the field's vertical component are told apart only by how much that component
varies). With --noisy DRIVE it calibrates the drive with sensor noise for each seed and prints error, std and error/std;
with --sweep DRIVE it only simulates the drive on other terrain seeds and reliefs and prints its tilt and the two
bounds.
Standard library only; recordings go to a temporary directory (--keep DIR keeps them).
"""
import argparse
import json
import math
import os
import re
import shutil
import subprocess
import sys
import tempfile

# Issue 3, "Numbers this must reach": the GPS lever arm's error norm, the IMU misalignment angle [deg], every element
# of A and b, k_v/L and k_theta relative, k_gamma [rad].
TARGETS = {"lever_norm": 0.10, "misalignment_deg": 2.0, "A": 0.02, "b": 0.01, "kv_rel": 0.005, "ktheta_rel": 0.005,
           "kgamma": 0.005}

# Handlebar and speed coupled: slow where the handlebar is turned most, so that v^2 tan(delta) / L stays < 0.45 g.
# atv_hills.yaml's drive.
WEAVE = """driver:
  type: ackermann
  lead_in_s: 4.0
  speed_mps:
    - constant: 3.5
    - sine: {amplitude: 1.2, period_s: 5.5, phase_rad: 1.5708}
  handlebar_rad:
    - sine: {amplitude: 0.40, period_s: 11.0, phase_rad: 0.0}
"""
# atv_hills_sines.yaml's drive: turns both ways (handlebar +-0.22 rad), speed 2.9-5.1 m/s.
SINES = """driver:
  type: ackermann
  lead_in_s: 4.0
  speed_mps:
    - constant: 4.0
    - sine: {amplitude: 0.8, period_s: 13.0, phase_rad: 0.0}
    - sine: {amplitude: 0.3, period_s: 4.7, phase_rad: 0.6}
  handlebar_rad:
    - sine: {amplitude: 0.15, period_s: 11.0, phase_rad: 0.3}
    - sine: {amplitude: 0.07, period_s: 3.7, phase_rad: 1.1}
"""
# Loops both ways (a figure eight every 17 s): the heading sweeps all directions, so every slope is crossed up and
# down and sideways.
LOOPS = """driver:
  type: ackermann
  lead_in_s: 4.0
  speed_mps:
    - constant: 3.2
    - sine: {amplitude: 0.8, period_s: 8.5, phase_rad: 1.5708}
  handlebar_rad:
    - sine: {amplitude: 0.45, period_s: 17.0, phase_rad: 0.0}
"""

# name: (description, substitutions): terrain_seed, relief_m, driver (a whole driver block).
DRIVES = {
    "default": ("atv_hills.yaml as it is (terrain seed 7, 4 m relief; the weave)", {}),
    "sines": ("atv_hills_sines.yaml: terrain 7, 4 m; handlebar +-0.22 rad, speed 2.9-5.1 m/s", {"driver": SINES}),
    "terrain9": ("sines, terrain seed 9", {"driver": SINES, "terrain_seed": 9}),
    "terrain11": ("sines, terrain seed 11", {"driver": SINES, "terrain_seed": 11}),
    "relief5": ("sines, 5 m relief", {"driver": SINES, "relief_m": 5.0}),
    "relief6": ("sines, 6 m relief", {"driver": SINES, "relief_m": 6.0}),
    "weave": ("terrain 7, 4 m; handlebar +-0.40 rad, speed 2.3-4.7 m/s", {"driver": WEAVE}),
    "loops": ("terrain 7, 4 m; figure eights, handlebar +-0.45 rad", {"driver": LOOPS}),
    "weave_relief5": ("weave, 5 m relief", {"driver": WEAVE, "relief_m": 5.0}),
    "loops_t11_relief5": ("loops, terrain seed 11, 5 m relief", {"driver": LOOPS, "terrain_seed": 11, "relief_m": 5.0}),
    "weave_relief6": ("weave, 6 m relief", {"driver": WEAVE, "relief_m": 6.0}),
    "weave_relief10": ("weave, 10 m relief: NOT admissible (the ATV slides), for scale",
                       {"driver": WEAVE, "relief_m": 10.0}),
}


def variant(scenario, drive, noise):
    """The scenario's text with the drive's substitutions (and every sensor noise zeroed unless noise)."""
    text = open(scenario).read()
    text = re.sub(r"model: *(\S+\.xml)",
                  lambda m: "model: " + os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(scenario)),
                                                                      m.group(1))), text)
    if not noise:
        text = re.sub(r"(_sigma_[a-z0-9]+|sigma_m|\bsigma): *[0-9.eE+-]+", r"\1: 0.0", text)

    def sub(pattern, replacement):
        nonlocal text
        text, n = re.subn(pattern, replacement, text, count=1, flags=re.M | re.S)
        if n != 1:
            sys.exit("atv_calibration_information: %s: no match for %r" % (scenario, pattern))

    if "terrain_seed" in drive:
        sub(r"^(    seed:) *\d+", r"\g<1> %d" % drive["terrain_seed"])
    if "relief_m" in drive:
        sub(r"^(    relief_m:) *[0-9.]+", r"\g<1> %g" % drive["relief_m"])
    if "driver" in drive:
        sub(r"^driver:\n.*?(?=^sensors:)", drive["driver"] + "\n")
    return text


def run(args, quiet=True):
    out = subprocess.run(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, universal_newlines=True)
    if out.returncode != 0:
        sys.exit("atv_calibration_information: %s failed:\n%s" % (" ".join(args), out.stderr[-2000:]))
    return out.stdout + out.stderr


def rotation(q):
    """Rotation matrix of q = (w, x, y, z)."""
    w, x, y, z = q
    return [[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]]


def transpose_times(r, v):
    return [sum(r[i][j] * v[i] for i in range(3)) for j in range(3)]


def inverse(m):
    """Gauss-Jordan inverse of a small symmetric positive definite matrix."""
    n = len(m)
    a = [list(row) + [1.0 if i == j else 0.0 for j in range(n)] for i, row in enumerate(m)]
    for c in range(n):
        p = max(range(c, n), key=lambda r: abs(a[r][c]))
        a[c], a[p] = a[p], a[c]
        pivot = a[c][c]
        a[c] = [x / pivot for x in a[c]]
        for r in range(n):
            if r != c and a[r][c] != 0.0:
                f = a[r][c]
                a[r] = [x - f * y for x, y in zip(a[r], a[c])]
    return [row[n:] for row in a]


def read_truth(rec):
    text = open(os.path.join(rec, "truth.yaml")).read()

    def values(name):
        m = re.search(re.escape(name) + r": *\[?([^\]\n]*)\]?", text)
        return [float(v) for v in m.group(1).split(",")]

    return {n: values(n) for n in ("gps.lever_arm", "imu.misalignment", "magnetometer.A", "magnetometer.b",
                                    "odometer.kv_over_L", "odometer.k_theta", "odometer.k_gamma")}


def read_poses(rec):
    poses = []
    for line in open(os.path.join(rec, "ground_truth.tum")):
        if line.startswith("#"):
            continue
        t, x, y, z, qx, qy, qz, qw = (float(v) for v in line.split())
        poses.append((t, (x, y, z), (qw, qx, qy, qz)))
    return poses


def drive_statistics(poses):
    """Roll and pitch of O (ZYX Euler angles) [deg], heading span [deg], peak v omega_z [g] over 0.2 s means."""
    roll, pitch, yaw = [], [], []
    for _, _, q in poses:
        r = rotation(q)
        pitch.append(math.degrees(math.asin(max(-1.0, min(1.0, -r[2][0])))))
        roll.append(math.degrees(math.atan2(r[2][1], r[2][2])))
        yaw.append(math.atan2(r[1][0], r[0][0]))
    unwrapped = [yaw[0]]
    for a in yaw[1:]:
        unwrapped.append(unwrapped[-1] + math.remainder(a - unwrapped[-1], 2 * math.pi))
    dt = poses[1][0] - poses[0][0]
    half = max(1, int(round(0.1 / dt)))
    lateral = []
    for k in range(half, len(poses) - half):
        (x0, y0, _), (x1, y1, _) = poses[k - half][1], poses[k + half][1]
        v = math.hypot(x1 - x0, y1 - y0) / (2 * half * dt)
        omega = (unwrapped[k + half] - unwrapped[k - half]) / (2 * half * dt)
        lateral.append(abs(v * omega) / 9.80665)

    def rms_about_mean(a):
        m = sum(a) / len(a)
        return math.sqrt(sum((x - m) ** 2 for x in a) / len(a))

    return {"roll_rms": rms_about_mean(roll), "roll_range": max(roll) - min(roll), "pitch_rms": rms_about_mean(pitch),
            "pitch_range": max(pitch) - min(pitch),
            "heading_span": math.degrees(max(unwrapped) - min(unwrapped)), "lateral_g": max(lateral)}


def known_trajectory_bounds(poses, truth, gps_rate_hz, gps_sigma, mag_sigma):
    """Least-squares std of the lever arm's height (fixes = O + R l + offset) and of b (m = A R_bi^T R^T f + b) with
    the true poses and misalignment known: lower bounds of what the calibration can reach."""
    step = int(round(1.0 / (gps_rate_hz * (poses[1][0] - poses[0][0]))))
    info = [[0.0] * 6 for _ in range(6)]
    for _, _, q in poses[::step]:
        r = rotation(q)
        rows = [r[i] + [1.0 if i == j else 0.0 for j in range(3)] for i in range(3)]
        for row in rows:
            for a in range(6):
                for b in range(6):
                    info[a][b] += row[a] * row[b] / gps_sigma ** 2
    lever_cov = inverse(info)
    field = [0.0, 0.5, -math.sqrt(0.75)]
    r_bi = rotation(truth["imu.misalignment"])
    info = [[0.0] * 4 for _ in range(4)]
    for _, _, q in poses:
        m = transpose_times(r_bi, transpose_times(rotation(q), field)) + [1.0]
        for a in range(4):
            for b in range(4):
                info[a][b] += m[a] * m[b] / mag_sigma ** 2
    mag_cov = inverse(info)
    return {"lever_z": math.sqrt(lever_cov[2][2]), "A": max(math.sqrt(mag_cov[i][i]) for i in range(3)),
            "b": math.sqrt(mag_cov[3][3])}


def table_row(calibration, truth):
    """Reported std of each target quantity (and the errors, for a noisy recording)."""
    p = calibration["parameters"]

    def std(name):
        return [s if s is not None else float("nan") for s in p[name]["std"]]

    def error(name):
        return [e - t for e, t in zip(p[name]["estimate"], truth[name])]

    lever_std = std("gps.lever_arm")
    q_est, q_true = p["imu.misalignment"]["estimate"], truth["imu.misalignment"]
    dot = abs(sum(a * b for a, b in zip(q_est, q_true))) / math.sqrt(sum(a * a for a in q_est) *
                                                                    sum(a * a for a in q_true))
    mis_std = [s for s in p["imu.misalignment"]["std"] if s is not None]
    kv, kth = truth["odometer.kv_over_L"][0], truth["odometer.k_theta"][0]
    return {
        "lever_std": lever_std, "lever_norm_std": math.sqrt(sum(s * s for s in lever_std)),
        "lever_error": error("gps.lever_arm"),
        "mis_std_deg": math.degrees(math.sqrt(sum(s * s for s in mis_std))),
        "mis_unobservable": len(mis_std) < 3, "mis_error_deg": math.degrees(2 * math.acos(min(1.0, dot))),
        "A_std": std("magnetometer.A"), "A_error": error("magnetometer.A"),
        "b_std": std("magnetometer.b"), "b_error": error("magnetometer.b"),
        "kv_std": std("odometer.kv_over_L")[0] / kv, "kv_error": error("odometer.kv_over_L")[0] / kv,
        "ktheta_std": std("odometer.k_theta")[0] / kth, "ktheta_error": error("odometer.k_theta")[0] / kth,
        "kgamma_std": std("odometer.k_gamma")[0], "kgamma_error": error("odometer.k_gamma")[0],
    }


def simulate(opts, scenario_path, rec, seed):
    """Runs the simulation; returns the side slip it reports [m/s] (the largest lateral velocity of the tires)."""
    out = run([opts.roamlab, "simulate", scenario_path, "--out", rec, "--seed", str(seed)])
    slip = re.search(r"side slip <= *([0-9.eE+-]+) m/s", out)
    if not slip:
        sys.exit("atv_calibration_information: simulate printed no side slip for %s" % scenario_path)
    return float(slip.group(1))


def simulate_and_calibrate(opts, name, noise, seed, work):
    out = os.path.join(work, "%s_%s" % (name, "seed%d" % seed if noise else "noiseless"))
    os.makedirs(out, exist_ok=True)
    path = os.path.join(out, "scenario.yaml")
    open(path, "w").write(variant(opts.scenario, DRIVES[name][1], noise))
    rec, cal = os.path.join(out, "rec"), os.path.join(out, "cal")
    side_slip = simulate(opts, path, rec, seed)
    run([opts.roamlab, "calibrate", rec, "--config", opts.config, "--out", cal, "--quiet"])
    calibration = json.load(open(os.path.join(cal, "calibration.json")))
    return rec, calibration, side_slip


def configured_noise(config_path):
    """sigma_GPS [m] and sigma_MAG of the configuration's gps and magnetometer streams."""
    config = open(config_path).read()
    gps = re.search(r"^  gps:\n.*?sigma_m: *([0-9.eE+-]+)", config, re.M | re.S)
    mag = re.search(r"^  magnetometer:\n.*?sigma: *([0-9.eE+-]+)", config, re.M | re.S)
    if not gps or not mag:
        sys.exit("atv_calibration_information: %s: no gps or magnetometer stream noise" % config_path)
    return float(gps.group(1)), float(mag.group(1))


def information_table(opts, work):
    gps_sigma, mag_sigma = configured_noise(opts.config)
    print("Reported std of the calibration on noise-free recordings (= Cramer-Rao bound of %s), per drive;" %
          opts.config)
    print("'known traj.': least-squares bound with the true trajectory known up to an offset (sigma_GPS %g, "
          "sigma_MAG %g)." % (gps_sigma, mag_sigma))
    print()
    print("| drive | roll rms / range [deg] | pitch rms / range [deg] | heading span [deg] | peak a_lat [g], side slip "
          "[m/s] "
          "| lever std x, y, z [m] (known traj. z) | misalignment [deg] | A max std | b max std (known traj.) "
          "| kv/L [%] | k_theta [%] (noise-free error) | k_gamma [rad] |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    print("| target (Table I) | | | | < 0.45, - | norm %.2f | %.1f | %.2f | %.2f | %.1f | %.1f | %.3f |" % (
        TARGETS["lever_norm"], TARGETS["misalignment_deg"], TARGETS["A"], TARGETS["b"], 100 * TARGETS["kv_rel"],
        100 * TARGETS["ktheta_rel"], TARGETS["kgamma"]))
    for name in opts.drives:
        rec, calibration, side_slip = simulate_and_calibrate(opts, name, False, 1, work)
        truth = read_truth(rec)
        poses = read_poses(rec)
        s = drive_statistics(poses)
        bounds = known_trajectory_bounds(poses, truth, 5.0, gps_sigma, mag_sigma)
        r = table_row(calibration, truth)
        print("| %s | %.1f / %.1f | %.1f / %.1f | %.0f | %.2f, %.2f | %.3f, %.3f, %.3f (%.3f) | %.2f%s | %.3f "
              "| %.3f (%.3f) | %.3f | %.2f (%+.2f) | %.4f |" % (
                  name, s["roll_rms"], s["roll_range"], s["pitch_rms"], s["pitch_range"], s["heading_span"],
                  s["lateral_g"], side_slip, r["lever_std"][0], r["lever_std"][1], r["lever_std"][2],
                  bounds["lever_z"],
                  r["mis_std_deg"], " (roll null)" if r["mis_unobservable"] else "", max(r["A_std"]),
                  max(r["b_std"]), bounds["b"], 100 * r["kv_std"], 100 * r["ktheta_std"], 100 * r["ktheta_error"],
                  r["kgamma_std"]))
        sys.stdout.flush()
    print()
    for name in opts.drives:
        print("%s: %s" % (name, DRIVES[name][0]))


def terrain_sweep(opts, work):
    """Only the drive and the known-trajectory bounds (no calibration) of DRIVE on terrain seeds and reliefs."""
    gps_sigma, mag_sigma = configured_noise(opts.config)
    name = opts.sweep
    print("Drive %s (%s) on other terrains, noise-free: tilt and the known-trajectory bounds" % (name, DRIVES[name][0]))
    print()
    print("| terrain seed | relief [m] | roll rms / range [deg] | pitch rms / range [deg] | peak a_lat [g], side slip "
          "[m/s] | lever z bound [m] | b bound | A bound |")
    print("|---|---|---|---|---|---|---|---|")
    for relief in opts.reliefs:
        for seed in opts.terrain_seeds:
            drive = dict(DRIVES[name][1], terrain_seed=seed, relief_m=relief)
            out = os.path.join(work, "%s_terrain%d_relief%g" % (name, seed, relief))
            os.makedirs(out, exist_ok=True)
            path = os.path.join(out, "scenario.yaml")
            open(path, "w").write(variant(opts.scenario, drive, False))
            rec = os.path.join(out, "rec")
            side_slip = simulate(opts, path, rec, 1)
            poses = read_poses(rec)
            st = drive_statistics(poses)
            b = known_trajectory_bounds(poses, read_truth(rec), 5.0, gps_sigma, mag_sigma)
            print("| %d | %g | %.1f / %.1f | %.1f / %.1f | %.2f, %.2f | %.3f | %.3f | %.3f |" % (
                seed, relief, st["roll_rms"], st["roll_range"], st["pitch_rms"], st["pitch_range"], st["lateral_g"],
                side_slip, b["lever_z"], b["b"], b["A"]))
            sys.stdout.flush()


def noisy_table(opts, work):
    name = opts.noisy
    print("Drive %s (%s) with the sensor noise, calibrated with %s: error (error / reported std)" % (
        name, DRIVES[name][0], opts.config))
    print()
    print("| seed | lever error [m] (/std) | misalignment [deg] | A max error (max /std) | b max error (max /std) "
          "| kv/L [%] | k_theta [%] | k_gamma [rad] |")
    print("|---|---|---|---|---|---|---|---|")

    def worst(errors, stds):
        ratio = max(abs(e) / s for e, s in zip(errors, stds) if s == s)
        return max(abs(e) for e in errors), ratio

    for seed in opts.seeds:
        rec, calibration, _ = simulate_and_calibrate(opts, name, True, seed, work)
        r = table_row(calibration, read_truth(rec))
        a, a_ratio = worst(r["A_error"], r["A_std"])
        b, b_ratio = worst(r["b_error"], r["b_std"])
        lever = ", ".join("%.3f (%.1f)" % (e, e / s) for e, s in zip(r["lever_error"], r["lever_std"]))
        print("| %d | %s; norm %.3f | %.2f | %.3f (%.1f) | %.3f (%.1f) | %.3f (%.1f) | %.2f (%.1f) | %.4f (%.1f) |" % (
            seed, lever, math.sqrt(sum(e * e for e in r["lever_error"])), r["mis_error_deg"], a, a_ratio, b, b_ratio,
            100 * r["kv_error"], r["kv_error"] / r["kv_std"], 100 * r["ktheta_error"],
            r["ktheta_error"] / r["ktheta_std"], r["kgamma_error"], r["kgamma_error"] / r["kgamma_std"]))
        sys.stdout.flush()


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--roamlab", default="build/apps/roamlab")
    ap.add_argument("--scenario", default="scenarios/atv_hills.yaml")
    ap.add_argument("--config", default="configs/atv_calibration.yaml")
    ap.add_argument("--drives", default=",".join(DRIVES), help="comma-separated names of DRIVES")
    ap.add_argument("--noisy", help="calibrate this drive with sensor noise instead (seeds --seeds)")
    ap.add_argument("--seeds", default="1,2,3")
    ap.add_argument("--sweep", help="only simulate this drive on --terrain-seeds x --reliefs (bounds, no calibration)")
    ap.add_argument("--terrain-seeds", default="7,8,9,10,11,12,13,14,15,16")
    ap.add_argument("--reliefs", default="4,5")
    ap.add_argument("--keep", help="keep the scenarios, recordings and calibrations in this directory")
    opts = ap.parse_args()
    opts.drives = opts.drives.split(",")
    opts.seeds = [int(s) for s in opts.seeds.split(",")]
    opts.terrain_seeds = [int(s) for s in opts.terrain_seeds.split(",")]
    opts.reliefs = [float(r) for r in opts.reliefs.split(",")]
    for name in opts.drives + [d for d in (opts.noisy, opts.sweep) if d]:
        if name not in DRIVES:
            sys.exit("atv_calibration_information: unknown drive %r (known: %s)" % (name, ", ".join(DRIVES)))
    work = opts.keep or tempfile.mkdtemp(prefix="atv_information_")
    try:
        if opts.noisy:
            noisy_table(opts, work)
        elif opts.sweep:
            terrain_sweep(opts, work)
        else:
            information_table(opts, work)
    finally:
        if not opts.keep:
            shutil.rmtree(work)


if __name__ == "__main__":
    main()
