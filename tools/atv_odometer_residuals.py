#!/usr/bin/env python3
"""What eq. 15's rows see on the nominal MuJoCo ATV: an analysis tool (it reads the truth; the estimator never does).

    python3 tools/atv_odometer_residuals.py [--roamlab build/apps/roamlab] [--scenario scenarios/atv_hills.yaml]
                                              [--drive NAME]
                                              [--seed 1] [--height 0.28] [--lever 0.625] [--t0 2] [--rolling-kv]

Simulates the scenario (with --drive, its variant of tools/atv_calibration_information.py's DRIVES, e.g. `sines`,
the drive of atv_hills_sines.yaml) with every sensor noise set to zero, then takes the velocities between consecutive
ground-truth poses of O (eq. 7 inverted, as the estimator does) and the true calibration, the speed read through the
geometric kv/L (truth.yaml's kv_over_L_geometric, as the configurations' noise was fitted; with --rolling-kv through
its kv_over_L, the tires' rolling value, whose smaller offset the calibrated kv/L would absorb), and prints, for the
rows of estimator/models/ackermann_velocity.h: their RMS, 1/e correlation time and white-noise equivalent (the
per-sample sigma of white noise with the same low-frequency power, sqrt of the summed autocovariance over +-3 s), at O and at the
rear ground contact (--height below O, vertical chord lever --lever), and least-squares slopes on the body rates and
the lateral acceleration, and each row's split into a first-order Gauss-Markov part (stationary sigma, correlation
time tau) and a white part, with the fit's white equivalent (the Bartlett-weighted sum above, over +-3 s, falls short
of it for correlation times of a second or more). Then the speed gain kv/L the speed row alone fits to the drive.
Last, the IMU's rows against the same poses: their model error
(the readings are instantaneous samples, the estimator's rates and accelerations come from the poses). Standard
library only.
"""
import argparse
import csv
import math
import os
import re
import subprocess
import tempfile


def qmul(a, b):
    w1, x1, y1, z1 = a
    w2, x2, y2, z2 = b
    return (w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2, w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
            w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2, w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2)


def qconj(a):
    return (a[0], -a[1], -a[2], -a[3])


def qlog(q):
    w, x, y, z = q if q[0] >= 0 else tuple(-c for c in q)
    n = math.sqrt(x * x + y * y + z * z)
    if n < 1e-12:
        return (2 * x, 2 * y, 2 * z)
    a = 2 * math.atan2(n, w)
    return (a * x / n, a * y / n, a * z / n)


def qexp(v):
    n = math.sqrt(sum(c * c for c in v))
    s = 0.5 if n < 1e-12 else math.sin(n / 2) / n
    return (math.cos(n / 2), v[0] * s, v[1] * s, v[2] * s)


def rotate(q, v):
    return qmul(qmul(q, (0.0,) + tuple(v)), qconj(q))[1:]


def rms(a):
    return math.sqrt(sum(x * x for x in a) / len(a))


def centred(a):
    m = sum(a) / len(a)
    return [x - m for x in a]


def correlation_time(a, dt):
    a = centred(a)
    c0 = sum(x * x for x in a)
    for lag in range(1, len(a) // 2):
        if sum(a[i] * a[i + lag] for i in range(len(a) - lag)) / c0 < math.exp(-1):
            return lag * dt
    return float("nan")


def white_equivalent(a, lags):
    """Per-sample sigma of white noise with a's power at zero frequency (Bartlett-weighted autocovariance sum)."""
    a = centred(a)
    n = len(a)
    s = sum(x * x for x in a) / n
    for lag in range(1, lags):
        s += 2 * (1 - lag / lags) * sum(a[i] * a[i + lag] for i in range(n - lag)) / n
    return math.sqrt(max(s, 0.0))


def gauss_markov_fit(a, dt):
    """First-order Gauss-Markov part plus white noise: (sigma, tau, white) with the autocovariance sigma^2
    exp(-|lag| dt / tau) + white^2 [lag = 0]. tau from the lags >= 1 (the 1/e point of c(lag) / c(1), one lag added
    back), sigma^2 = c(1) exp(dt / tau) (c extrapolated to lag 0), white^2 = c(0) - sigma^2."""
    a = centred(a)
    n = len(a)

    def c(lag):
        return sum(a[i] * a[i + lag] for i in range(n - lag)) / n
    c0, c1 = c(0), c(1)
    tau = float("nan")
    for lag in range(2, n // 2):
        if c(lag) < c1 * math.exp(-1):
            tau = (lag - 1) * dt
            break
    sigma2 = min(c1 * math.exp(dt / tau), c0)
    return math.sqrt(sigma2), tau, math.sqrt(max(c0 - sigma2, 0.0))


def least_squares(y, columns):
    """Slopes of y on [1, columns...] and the residual RMS (normal equations, Gauss-Jordan)."""
    X = [[1.0] + [c[i] for c in columns] for i in range(len(y))]
    n = len(X[0])
    M = [[sum(r[a] * r[b] for r in X) for b in range(n)] + [sum(r[a] * yi for r, yi in zip(X, y))] for a in range(n)]
    for c in range(n):
        p = max(range(c, n), key=lambda r: abs(M[r][c]))
        M[c], M[p] = M[p], M[c]
        for r in range(n):
            if r != c:
                f = M[r][c] / M[c][c]
                M[r] = [u - f * v for u, v in zip(M[r], M[c])]
    b = [M[i][n] / M[i][i] for i in range(n)]
    return b, rms([yi - sum(bj * xj for bj, xj in zip(b, r)) for r, yi in zip(X, y)])


def simulate_noiseless(roamlab, scenario, seed, out):
    text = open(scenario).read()
    text = re.sub(r"(_sigma_[a-z0-9]+|sigma_m|\bsigma): *[0-9.eE+-]+", r"\1: 0.0", text)
    text = re.sub(r"model: *(\S+\.xml)",
                  lambda m: "model: " + os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(scenario)),
                                                                      m.group(1))), text)
    path = os.path.join(out, "noiseless.yaml")
    open(path, "w").write(text)
    subprocess.run([roamlab, "simulate", path, "--out", os.path.join(out, "rec"), "--seed", str(seed), "--quiet"],
                   check=True)
    return os.path.join(out, "rec")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--roamlab", default="build/apps/roamlab")
    ap.add_argument("--scenario", default="scenarios/atv_hills.yaml")
    ap.add_argument("--drive", help="a drive of atv_calibration_information.py's DRIVES instead of the scenario's")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--height", type=float, default=0.28, help="contact below O [m]")
    ap.add_argument("--lever", type=float, default=0.625, help="vertical row's pitch-rate lever [m]")
    ap.add_argument("--t0", type=float, default=2.0, help="skip the first seconds [s]")
    ap.add_argument("--rolling-kv", action="store_true",
                    help="read the speed through truth.yaml's kv_over_L (the tires' rolling value), not the geometric")
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        scenario = args.scenario
        if args.drive:
            import atv_calibration_information as information
            if args.drive not in information.DRIVES:
                raise SystemExit("atv_odometer_residuals: unknown drive '%s' (known: %s)" %
                                 (args.drive, ", ".join(information.DRIVES)))
            scenario = os.path.join(tmp, "drive.yaml")
            open(scenario, "w").write(information.variant(args.scenario, information.DRIVES[args.drive][1], True))
        rec = simulate_noiseless(args.roamlab, scenario, args.seed, tmp)
        truth = open(os.path.join(rec, "truth.yaml")).read()
        kv_rolling = float(re.search(r"odometer.kv_over_L: *([0-9.eE+-]+)", truth).group(1))
        kv_geometric = float(re.search(r"odometer.kv_over_L_geometric: *([0-9.eE+-]+)", truth).group(1))
        kv_over_l = kv_rolling if args.rolling_kv else kv_geometric
        k_theta = float(re.search(r"odometer.k_theta: *([0-9.eE+-]+)", truth).group(1))
        k_gamma = float(re.search(r"odometer.k_gamma: *([0-9.eE+-]+)", truth).group(1))
        wheelbase = float(re.search(r"wheelbase_m: *([0-9.eE+-]+)", open(os.path.join(rec, "recording.yaml")).read())
                          .group(1))
        poses = []
        for line in open(os.path.join(rec, "ground_truth.tum")):
            if line.strip() and not line.startswith("#"):
                f = [float(x) for x in line.split()]
                poses.append((f[0], f[1:4], (f[7], f[4], f[5], f[6])))

        def column(name):
            rows = list(csv.reader(open(os.path.join(rec, name))))[1:]
            return {round(float(r[0]) * 1e3): float(r[1]) for r in rows}
        speed, steering = column("rear_wheel.csv"), column("steering.csv")
        misalignment = [float(x) for x in
                        re.search(r"imu.misalignment: *\[([^\]]*)\]", truth).group(1).split(",")]
        imu = {round(float(r[0]) * 1e3): [float(x) for x in r[1:7]]
               for r in list(csv.reader(open(os.path.join(rec, "imu.csv"))))[1:]}
    samples = []
    rolls = []  # sin of O's roll at the middle of each sample's interval: e_z^T R_mid e_y
    for (t0, p0, q0), (t1, p1, q1) in zip(poses, poses[1:]):
        key = round(t0 * 1e3)
        if t0 < args.t0 or key not in speed:
            continue
        dt = t1 - t0
        phi = qlog(qmul(qconj(q0), q1))
        w = [c / dt for c in phi]
        v = rotate(qconj(qmul(q0, qexp([c / 2 for c in phi]))), [(b - a) / dt for a, b in zip(p0, p1)])
        if v[0] < 0.5:
            continue
        samples.append((v, w, speed[key] * kv_over_l * wheelbase, k_theta * steering[key] + k_gamma))
        rolls.append(rotate(qmul(q0, qexp([c / 2 for c in phi])), [0.0, 1.0, 0.0])[2])
    dt = poses[1][0] - poses[0][0]
    lags = int(round(3.0 / dt))
    a_y = [s[0][0] * s[1][2] for s in samples]
    w_x = [s[1][0] for s in samples]
    w_y = [s[1][1] for s in samples]
    print("%d samples of %.0f ms after %.1f s; L = %.3f m, h = %.3f m, d = %.3f m" %
          (len(samples), dt * 1e3, args.t0, wheelbase, args.height, args.lever))
    print("%-34s %8s %8s %8s %10s" % ("row (true readings, no noise)", "mean", "rms", "1/e [s]", "white-eq"))
    for label, h, d in (("at O (eq. 15)", 0.0, 0.0), ("at the contact", args.height, args.lever)):
        rows = {"speed [m/s]": [], "lateral v_y [m/s]": [], "vertical v_z [m/s]": [], "steering [rad]": []}
        for v, w, speed_mps, delta in samples:
            c = (v[0] - h * w[1], v[1] + h * w[0], v[2] - d * w[1])
            rows["speed [m/s]"].append(c[0] - speed_mps)
            rows["lateral v_y [m/s]"].append(c[1])
            rows["vertical v_z [m/s]"].append(c[2])
            rows["steering [rad]"].append(math.atan((wheelbase * w[2] + c[1]) / c[0]) - delta)
        print(label)
        for name, a in rows.items():
            print("  %-32s %+8.4f %8.4f %8.2f %10.4f" % (name, sum(a) / len(a), rms(a), correlation_time(a, dt),
                                                       white_equivalent(a, lags)))
        if h == 0.0:
            for name, y, cols, labels in (
                    ("speed", rows["speed [m/s]"], [w_y], ["omega_y"]),
                    ("lateral", rows["lateral v_y [m/s]"], [a_y, w_x], ["a_y", "omega_x"]),
                    ("vertical", rows["vertical v_z [m/s]"], [w_y], ["omega_y"]),
                    ("steering", rows["steering [rad]"], [a_y], ["a_y"])):
                b, r = least_squares(y, cols)
                print("    %-9s slopes %s, residual rms %.4f" %
                      (name, ", ".join("%+.4f on %s" % (bj, lj) for bj, lj in zip(b[1:], labels)), r))
        else:
            lat = rows["lateral v_y [m/s]"]
            b_lat, _ = least_squares(lat, [a_y])
            b_str, _ = least_squares(rows["steering [rad]"], [a_y])
            lat_left = [y - b_lat[1] * a for y, a in zip(lat, a_y)]
            str_left = [y - b_str[1] * a for y, a in zip(rows["steering [rad]"], a_y)]
            # The understeer as the front axle's side slip velocity c a_y (option front_slip_velocity): to first order
            # the row moves by c a_y cos^2(kin) / v_x, kin = atan((L omega_z + v_y) / v_x) at the contact.
            slip_regressor = [a * math.cos(math.atan((wheelbase * w[2] + v[1] + h * w[0]) / (v[0] - h * w[1]))) ** 2 /
                              (v[0] - h * w[1]) for a, (v, w, _, _) in zip(a_y, samples)]
            b_slip, _ = least_squares(rows["steering [rad]"], [slip_regressor])
            slip_left = [y - b_slip[1] * a for y, a in zip(rows["steering [rad]"], slip_regressor)]
            print("    cornering: lateral %+.4f s on a_y, steering %+.4f rad s^2/m (as the front axle's slip velocity "
                  "%+.4f s); after them:" % (b_lat[1], b_str[1], b_slip[1]))
            for name, a in (("lateral v_y [m/s]", lat_left), ("steering [rad]", str_left),
                            ("steering, slip velocity [rad]", slip_left)):
                print("  %-32s %+8.4f %8.4f %8.2f %10.4f" % (name, sum(a) / len(a), rms(a), correlation_time(a, dt),
                                                           white_equivalent(a, lags)))
            print("  Gauss-Markov part + white part at the contact (after cornering):")
            print("  %-32s %8s %8s %8s %10s" % ("", "GM sigma", "GM tau", "white", "white-eq"))
            for name, a in (("speed [m/s]", rows["speed [m/s]"]), ("lateral v_y [m/s]", lat_left),
                            ("vertical v_z [m/s]", rows["vertical v_z [m/s]"]), ("steering [rad]", str_left),
                            ("steering, slip velocity [rad]", slip_left)):
                sigma, tau, white = gauss_markov_fit(a, dt)
                # The fitted process's power at zero frequency as white noise per sample: the Gauss-Markov part's
                # autocovariance summed over all lags, sigma^2 (1 + rho) / (1 - rho) with rho = exp(-dt / tau).
                rho = math.exp(-dt / tau)
                print("  %-32s %8.4f %8.2f %8.4f %10.4f" % (name, sigma, tau, white,
                                                           math.sqrt(sigma ** 2 * (1 + rho) / (1 - rho) + white ** 2)))

    speed_gains(samples, rolls, kv_over_l, kv_rolling, kv_geometric, args.height)
    imu_rows(poses, imu, misalignment, args.t0)


def speed_gains(samples, rolls, kv_over_l, kv_rolling, kv_geometric, h):
    """The speed gain kv/L the speed row alone fits to the drive (least squares of the row's speed on the reading, as
    a calibration of kv/L alone does), relative to truth.yaml's geometric kv/L: with the row at O, at the contact h
    below O, and at the contact with the yaw rate a rolled chassis shows about its y axis (omega_z sin(roll)) taken
    out of the pitch rate (on level ground, where the roll is the suspension's); beside it truth.yaml's kv/L, the
    tires' free-rolling value; and the roll's slope on the lateral acceleration."""
    wheel = [s[2] * kv_geometric / kv_over_l for s in samples]  # the reading times the geometric k_v: omega r
    print("speed gain the speed row fits, relative to the geometric kv/L %.4f (truth.yaml's kv/L: %+.3f %%)" %
          (kv_geometric, 100 * (kv_rolling / kv_geometric - 1)))
    for label, rows in (
            ("at O", [v[0] for v, _, _, _ in samples]),
            ("at the contact", [v[0] - h * w[1] for v, w, _, _ in samples]),
            ("at the contact, yaw-in-roll out of omega_y",
             [v[0] - h * (w[1] - w[2] * r) for (v, w, _, _), r in zip(samples, rolls)])):
        gain = sum(c * c for c in rows) / sum(c * z for c, z in zip(rows, wheel))
        print("  %-44s %+.3f %%" % (label, 100 * (gain - 1)))
    b, r = least_squares(rolls, [[v[0] * w[2] for v, w, _, _ in samples]])
    print("  sin(roll) %+.4f rad s^2/m on a_y, residual rms %.4f (on level ground: the roll on the suspension)" %
          (b[1], r))


def block_equivalent(a, n):
    """Per-sample sigma of white noise whose sums over n samples spread as a's do (a's mean removed)."""
    a = centred(a)
    sums = [sum(a[i:i + n]) for i in range(0, len(a) - n + 1, n)]
    return math.sqrt(sum(x * x for x in sums) / len(sums) / n)


def imu_rows(poses, imu, misalignment, t0_s):
    """The IMU's rows against the true poses of O (IMU at O, true misalignment): the gyroscope's reading against the
    rate over the interval that starts at it (Log(q_k^-1 q_k+1) / dt), the accelerometer's against the specific
    force from the second difference of the positions at the middle pose (estimator/models/gyroscope.h,
    accelerometer.h). Per body axis: rms, and the per-sample sigma of white noise whose sums over 0.2 s and 1 s
    spread alike (a white error keeps it; a slow one grows)."""
    gyro, accel = [], []
    for (_, p0, _), (t1, p1, q1), (t2, p2, q2) in zip(poses, poses[1:], poses[2:]):
        key = round(t1 * 1e3)
        if t1 < t0_s or key not in imu:
            continue
        dt = t2 - t1
        gyro.append([r - w / dt for r, w in zip(rotate(misalignment, imu[key][:3]), qlog(qmul(qconj(q1), q2)))])
        a_world = [(c - 2 * b + a) / (dt * dt) for a, b, c in zip(p0, p1, p2)]
        a_world[2] += 9.80665
        accel.append([r - f for r, f in zip(rotate(misalignment, imu[key][3:]), rotate(qconj(q1), a_world))])
    n = round(0.2 / dt), round(1.0 / dt)
    print("IMU rows against the true poses (body axes x, y, z): rms; white equivalent over 0.2 s and 1 s")
    for name, rows in (("gyroscope [rad/s]", gyro), ("accelerometer [m/s^2]", accel)):
        print("  %-22s %s" % (name, "   ".join(
            "%s %.4f; %.4f %.4f" % ("xyz"[i], rms([r[i] for r in rows]), block_equivalent([r[i] for r in rows], n[0]),
                                   block_equivalent([r[i] for r in rows], n[1])) for i in range(3))))


if __name__ == "__main__":
    main()
