#!/usr/bin/env python3
"""Which steering-row model holds across drives on the nominal MuJoCo ATV: an analysis tool (it reads the truth; the
estimator never does).

    python3 tools/atv_understeer_fit.py [--roamlab build/apps/roamlab] [--scenario scenarios/atv_hills.yaml]
                                          [--drives default,weave] [--seed 1] [--height 0.28]

Simulates each drive (tools/atv_calibration_information.py's DRIVES) with every sensor noise set to zero, takes the
velocities between consecutive ground-truth poses of O at the rear ground contact (--height below O, as
estimator/models/ackermann_velocity.h with contact_height_m) and the true steered angle delta = k_theta z + k_gamma,
and fits the understeer u = delta - atan((L omega_z + v_y) / v_x) with candidate terms (least squares with an offset,
which k_gamma absorbs): per drive, and jointly on all drives. For the joint coefficients it prints each drive's
residual RMS, its white equivalent (a first-order Gauss-Markov fit's power at zero frequency as white noise per
sample, as tools/atv_odometer_residuals.py: the steering row's noise term) and k_theta's relative error: a
calibration that fixes the candidate's coefficients predicts delta minus the residual, so k_theta absorbs the
residual's slope on delta, negated. Standard library only.
"""
import argparse
import math
import os
import re
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import atv_calibration_information as information  # noqa: E402
import atv_odometer_residuals as residuals  # noqa: E402

# name: (description, regressors of a sample s = dict(a_y, v_x, delta, kin)); kin = atan((L omega_z + v_y) / v_x).
CANDIDATES = {
    "linear": ("c a_y [rad s^2/m] (the ackermann model's cornering_front)", [lambda s: s["a_y"]]),
    "slip_velocity": ("front axle's side slip c a_y [s]: delta = atan((L omega_z + v_y + c a_y) / v_x)",
                      [lambda s: s["a_y"] * math.cos(s["kin"]) ** 2 / s["v_x"]]),
    "cubic": ("c1 a_y + c3 a_y^3 (tire saturation, load transfer)", [lambda s: s["a_y"], lambda s: s["a_y"] ** 3]),
    "speed": ("c1 a_y + c2 a_y v_x", [lambda s: s["a_y"], lambda s: s["a_y"] * s["v_x"]]),
    "linear+slip_velocity": ("c1 a_y + c2 a_y / v_x", [lambda s: s["a_y"], lambda s: s["a_y"] / s["v_x"]]),
    "handlebar_cubic": ("c1 a_y + c2 delta^3 (geometry)", [lambda s: s["a_y"], lambda s: s["delta"] ** 3]),
}


def samples_of(rec, height_m, t0_s):
    truth = open(os.path.join(rec, "truth.yaml")).read()

    def value(name):
        return float(re.search(re.escape(name) + r": *([0-9.eE+-]+)", truth).group(1))
    k_theta, k_gamma = value("odometer.k_theta"), value("odometer.k_gamma")
    wheelbase = float(re.search(r"wheelbase_m: *([0-9.eE+-]+)",
                          open(os.path.join(rec, "recording.yaml")).read()).group(1))
    poses = information.read_poses(rec)
    steering = {}
    for line in open(os.path.join(rec, "steering.csv")).readlines()[1:]:
        t, z = line.split(",")[:2]
        steering[round(float(t) * 1e3)] = float(z)
    out = []
    for (t0, p0, q0), (t1, p1, q1) in zip(poses, poses[1:]):
        key = round(t0 * 1e3)
        if t0 < t0_s or key not in steering:
            continue
        dt = t1 - t0
        phi = residuals.qlog(residuals.qmul(residuals.qconj(q0), q1))
        w = [c / dt for c in phi]
        v = residuals.rotate(residuals.qconj(residuals.qmul(q0, residuals.qexp([c / 2 for c in phi]))),
                             [(b - a) / dt for a, b in zip(p0, p1)])
        v_x, v_y = v[0] - height_m * w[1], v[1] + height_m * w[0]
        if v_x < 0.5:
            continue
        kin = math.atan((wheelbase * w[2] + v_y) / v_x)
        delta = k_theta * steering[key] + k_gamma
        out.append({"a_y": v_x * w[2], "v_x": v_x, "delta": delta, "kin": kin, "u": delta - kin})
    return out


def fit(samples, regressors):
    b, _ = residuals.least_squares([s["u"] for s in samples], [[f(s) for s in samples] for f in regressors])
    return b


def left_over(samples, regressors, b):
    return [s["u"] - b[0] - sum(bj * f(s) for bj, f in zip(b[1:], regressors)) for s in samples]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--roamlab", default="build/apps/roamlab")
    ap.add_argument("--scenario", default="scenarios/atv_hills.yaml")
    ap.add_argument("--drives", default="default,weave")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--height", type=float, default=0.28, help="contact below O [m]")
    ap.add_argument("--t0", type=float, default=2.0, help="skip the first seconds [s]")
    args = ap.parse_args()
    drives = args.drives.split(",")
    for d in drives:
        if d not in information.DRIVES:
            sys.exit("atv_understeer_fit: unknown drive '%s' (known: %s)" % (d, ", ".join(information.DRIVES)))
    data = {}
    with tempfile.TemporaryDirectory() as tmp:
        for d in drives:
            os.makedirs(os.path.join(tmp, d))
            path = os.path.join(tmp, d, "scenario.yaml")
            open(path, "w").write(information.variant(args.scenario, information.DRIVES[d][1], noise=False))
            rec = residuals.simulate_noiseless(args.roamlab, path, args.seed, os.path.join(tmp, d))
            data[d] = samples_of(rec, args.height, args.t0)
            poses = information.read_poses(rec)
            dt = poses[1][0] - poses[0][0]
    for d in drives:
        s = data[d]
        print("%-13s %d samples: |a_y| max %.2f m/s^2, v_x %.1f-%.1f m/s, |delta| max %.3f rad, understeer rms %.4f rad"
              % (d, len(s), max(abs(x["a_y"]) for x in s), min(x["v_x"] for x in s), max(x["v_x"] for x in s),
                 max(abs(x["delta"]) for x in s), residuals.rms(centred_u(s))))
    everything = [x for d in drives for x in data[d]]
    print("per candidate: joint coefficients; per drive with them the residual's rms and white equivalent [rad] and "
          "k_theta's error [%] (own fit: coefficients, rms)")
    for name, (description, regressors) in CANDIDATES.items():
        b = fit(everything, regressors)
        print("%-21s %s" % (name, description))
        print("  joint: %s" % ", ".join("%+.5g" % x for x in b[1:]))
        for d in drives:
            r = left_over(data[d], regressors, b)
            slope, _ = residuals.least_squares(r, [[x["delta"] for x in data[d]]])
            own = fit(data[d], regressors)
            sigma, tau, white = residuals.gauss_markov_fit(r, dt)
            rho = math.exp(-dt / tau)
            print("  %-13s rms %.4f, white-eq %.4f, k_theta %+.2f %%   (own: %s, rms %.4f)" %
                  (d, residuals.rms(residuals.centred(r)), math.sqrt(sigma ** 2 * (1 + rho) / (1 - rho) + white ** 2),
                   -100 * slope[1], ", ".join("%+.5g" % x for x in own[1:]),
                   residuals.rms(left_over(data[d], regressors, own))))


def centred_u(samples):
    return residuals.centred([s["u"] for s in samples])


if __name__ == "__main__":
    main()
