#!/usr/bin/env python3
"""What constant wheel geometry can do for the OptiOdom differential drive's 10 s drift (a kinematic stand-in of the
twin: dead reckoning of the recorded encoder angles, compared with the motion capture as `roamlab diagnose` compares
the twin, gap/twin.h TwinDrift: 10 s windows every 1 s, each aligned by the noise-weighted planar rigid fit over its
first 2 s, the position error at its end).

Per run (run-01 of each set named): the nominal geometry's drift; the drift with the geometry fitted to that run's own
windows (an oracle: radius scale, right/left radius ratio and track error, as the twin's wheel_radius_scale,
wheel_radius_asymmetry and track_width_error set them; Nelder-Mead on the mean drift), the same
with a clock shift of the encoders against the motion capture fitted too, and the geometry fitted on a training run
(the first run named; several, comma-separated, fitted together on the mean over them of drift / nominal drift)
carried over; the motion capture's distance over the
encoders' on straight 1 s stretches, its heading change over the encoders' on arcs (1 s stretches with both wheels
forward, their angles differing by more than 5 %, turning by more than 0.05 rad) and on in-place turns (0.5 s stretches with the wheels turning
opposite ways), all with the nominal geometry.

With --best-common: the one geometry, the one geometry with one clock shift, and the one geometry with one clock
shift at the run's start drifting at one rate (the twin's drive_clock_drift), that minimize the largest drift ratio
(patched / nominal) over every run named, fitted on those runs themselves (Nelder-Mead from three starts): what the
best patch of each form can do on them, whatever it was trained on; and each run's motion-capture scatter (the white
noise of its positions and heading, from their third differences).

With --patch SCALE,RATIO,TRACK_ERROR_M[,SHIFT_S[,DRIFT_PPM]]: each run's drift with that one patch (a twin's fitted
patch, say) over its nominal drift.

With --local-clock SCALE,RATIO,TRACK_ERROR_M: per run, the encoders' clock shift that best fits each 15 s stretch
(every 7.5 s; 5 s windows aligned over 1 s, the shift searched from -60 to +160 ms in 10 ms steps) with that one
geometry: whether a run's clock shift is constant or drifts.

    python3 tools/optiodom_drift_floor.py DATA_DIR TRAINING_SET[,TRAINING_SET...] OTHER_SET...
    python3 tools/optiodom_drift_floor.py --best-common DATA_DIR SET...
    python3 tools/optiodom_drift_floor.py --local-clock SCALE,RATIO,TRACK_ERROR_M DATA_DIR SET...
    python3 tools/optiodom_drift_floor.py --patch SCALE,RATIO,TRACK_ERROR_M[,SHIFT_S[,DRIFT_PPM]] DATA_DIR SET...
      (DATA_DIR: the dataset's data/diff folder; a set as shape/name, e.g. square/231220200029)
"""
import bisect
import csv
import math
import pathlib
import sys

TICKS_PER_WHEEL_REV = 43.7 * 64  # gear ratio times encoder ticks per motor revolution
RADIUS_M, TRACK_M = 0.042, 0.2
POSITION_SIGMA_M, HEADING_SIGMA_RAD = 0.001, 0.005  # as the importer states the motion capture's noise


def load(path):
    """Stamps, motion-capture x, y, unwrapped heading, cumulative right and left wheel angles [rad]."""
    rows = [[float(v) for v in r[:6]] for r in csv.reader(open(path)) if r]
    run = {"t": [], "x": [], "y": [], "th": [], "right": [], "left": []}
    right = left = 0.0
    for r in rows:
        right += 2 * math.pi * r[4] / TICKS_PER_WHEEL_REV
        left += 2 * math.pi * r[5] / TICKS_PER_WHEEL_REV
        th = r[3] if not run["th"] else run["th"][-1] + math.remainder(r[3] - run["th"][-1], 2 * math.pi)
        for k, v in zip(run, (r[0], r[1], r[2], th, right, left)):
            run[k].append(v)
    return run


def geometry(p):
    """(scale, right/left ratio, track error [m]) -> right and left radius, track [m], as the twin's effects set them
    (wheel_radius_scale both radii, wheel_radius_asymmetry the right one): a patch reads the same in both."""
    scale, ratio, track_error = p
    return RADIUS_M * scale * ratio, RADIUS_M * scale, TRACK_M + track_error


def shifted(t, values, shift_s, drift=0.0):
    """values (at stamps t) read at t + shift_s + drift (t - t[0]), linearly interpolated, held at the ends."""
    out = []
    for q in t:
        q += shift_s + drift * (q - t[0])
        i = min(max(bisect.bisect_right(t, q), 1), len(t) - 1)
        a = min(max((q - t[i - 1]) / (t[i] - t[i - 1]), 0.0), 1.0)
        out.append(values[i - 1] + a * (values[i] - values[i - 1]))
    return out


def dead_reckon(run, p):
    """The pose from the encoder angles with geometry p[:3], the encoders read p[3] s later when given, and p[4] ppm of
    the time since the run's start later still when given (their clock's drift)."""
    r_right, r_left, track = geometry(p[:3])
    x, y, th = [0.0], [0.0], [0.0]
    for i in range(1, len(run["t"])):
        d_right = r_right * (run["right"][i] - run["right"][i - 1])
        d_left = r_left * (run["left"][i] - run["left"][i - 1])
        ds, dth = 0.5 * (d_right + d_left), (d_right - d_left) / track
        mid = th[-1] + 0.5 * dth
        x.append(x[-1] + ds * math.cos(mid))
        y.append(y[-1] + ds * math.sin(mid))
        th.append(th[-1] + dth)
    if len(p) > 3:
        drift = 1e-6 * p[4] if len(p) > 4 else 0.0
        return tuple(shifted(run["t"], v, p[3], drift) for v in (x, y, th))
    return x, y, th


def alignment(run, twin, a, e):
    """Yaw and translation of the twin onto the motion capture over samples a..e (gap/twin_compare.cc's fit)."""
    x, y, th = twin
    n = e - a + 1
    crx, cry = sum(run["x"][a:e + 1]) / n, sum(run["y"][a:e + 1]) / n
    ctx, cty = sum(x[a:e + 1]) / n, sum(y[a:e + 1]) / n
    sxx = sxy = hs = hc = 0.0
    for i in range(a, e + 1):
        rx, ry, tx, ty = run["x"][i] - crx, run["y"][i] - cry, x[i] - ctx, y[i] - cty
        sxx += tx * rx + ty * ry
        sxy += tx * ry - ty * rx
        hs += math.sin(run["th"][i] - th[i])
        hc += math.cos(run["th"][i] - th[i])
    d = math.atan2(hs, hc)
    positions, headings = math.hypot(sxx, sxy) / POSITION_SIGMA_M**2, n / HEADING_SIGMA_RAD**2
    yaw = d + positions / (positions + headings) * math.remainder(math.atan2(sxy, sxx) - d, 2 * math.pi)
    c, s = math.cos(yaw), math.sin(yaw)
    return yaw, crx - (c * ctx - s * cty), cry - (s * ctx + c * cty)


def drift(run, p, window_s=10.0, stride_s=1.0, align_s=2.0):
    """Mean position error [m] at the end of the windows."""
    t = run["t"]
    twin = dead_reckon(run, p)
    errors = []
    w0 = t[0]
    while w0 + window_s <= t[-1] + 1e-9:
        a = bisect.bisect_left(t, w0 - 1e-9)
        b = bisect.bisect_right(t, w0 + window_s + 1e-9) - 1
        e = min(bisect.bisect_right(t, t[a] + align_s + 1e-9) - 1, b - 1)
        yaw, px, py = alignment(run, twin, a, e)
        c, s = math.cos(yaw), math.sin(yaw)
        errors.append(math.hypot(c * twin[0][b] - s * twin[1][b] + px - run["x"][b],
                                 s * twin[0][b] + c * twin[1][b] + py - run["y"][b]))
        w0 += stride_s
    return sum(errors) / len(errors)


def nelder_mead(f, x0, steps, iterations=120):
    points = [list(x0)] + [[x0[j] + (steps[j] if j == i else 0.0) for j in range(len(x0))] for i in range(len(x0))]
    values = [f(p) for p in points]
    for _ in range(iterations):
        order = sorted(range(len(points)), key=values.__getitem__)
        points, values = [points[i] for i in order], [values[i] for i in order]
        centre = [sum(p[j] for p in points[:-1]) / (len(points) - 1) for j in range(len(x0))]
        toward = lambda k: [centre[j] + k * (points[-1][j] - centre[j]) for j in range(len(x0))]  # noqa: E731
        reflected = toward(-1.0)
        fr = f(reflected)
        if fr < values[0]:
            expanded = toward(-2.0)
            fe = f(expanded)
            points[-1], values[-1] = (expanded, fe) if fe < fr else (reflected, fr)
        elif fr < values[-2]:
            points[-1], values[-1] = reflected, fr
        else:
            contracted = toward(0.5)
            fc = f(contracted)
            if fc < values[-1]:
                points[-1], values[-1] = contracted, fc
            else:
                points = [points[0]] + [[points[0][j] + 0.5 * (p[j] - points[0][j]) for j in range(len(x0))]
                                        for p in points[1:]]
                values = [values[0]] + [f(p) for p in points[1:]]
    best = min(range(len(points)), key=values.__getitem__)
    return points[best], values[best]


def ratio(a, b):
    return a / b if b else math.nan


def motion_ratios(run):
    """Motion capture over encoders: distance on straight 1 s stretches, heading on arcs (1 s) and in-place turns
    (0.5 s)."""
    t, right, left, th = run["t"], run["right"], run["left"], run["th"]
    step = max(1, round(1.0 / (t[1] - t[0])))
    moved = rolled = arc_turned = arc_wheels = turned = wheels = 0.0
    for i in range(0, len(t) - step, step):
        j = i + step
        dr, dl = right[j] - right[i], left[j] - left[i]
        if dr <= 0 or dl <= 0:
            continue
        if abs(dr - dl) < 0.03 * (dr + dl) / 2 and abs(th[j] - th[i]) < 0.02:
            moved += math.hypot(run["x"][j] - run["x"][i], run["y"][j] - run["y"][i])
            rolled += RADIUS_M * (dr + dl) / 2
        elif abs(dr - dl) > 0.05 * (dr + dl) / 2 and abs(th[j] - th[i]) > 0.05:
            arc_turned += th[j] - th[i]
            arc_wheels += RADIUS_M * (dr - dl) / TRACK_M
    for i in range(0, len(t) - step // 2, step // 2):
        j = i + step // 2
        dr, dl = right[j] - right[i], left[j] - left[i]
        if dr * dl < 0:
            turned += th[j] - th[i]
            wheels += RADIUS_M * (dr - dl) / TRACK_M
    return ratio(moved, rolled), ratio(arc_turned, arc_wheels), ratio(turned, wheels)


def scatter(values):
    """The white noise of a smooth series: the robust spread of its third differences over sqrt(20)."""
    third = sorted(abs(values[i + 3] - 3 * values[i + 2] + 3 * values[i + 1] - values[i])
                   for i in range(len(values) - 3))
    return 1.4826 * third[len(third) // 2] / math.sqrt(20)


def best_common(runs):
    """Prints, for the geometry alone, with a clock shift and with a drifting clock, the patch minimizing the largest
    drift ratio."""
    for name, run in runs.items():
        print(f"{name}: motion capture's scatter x {1000 * scatter(run['x']):.2f} mm, y {1000 * scatter(run['y']):.2f} "
              f"mm, heading {1000 * scatter(run['th']):.1f} mrad")
    nominal = {name: drift(run, (1.0, 1.0, 0.0)) for name, run in runs.items()}
    ratios = lambda p: {name: drift(run, p) / nominal[name] for name, run in runs.items()}  # noqa: E731
    worst = lambda p: max(ratios(p).values())  # noqa: E731
    for label, starts, steps in (
            ("geometry", [(1.0, 1.0, 0.0), (0.995, 1.0, 0.002), (0.993, 1.002, 0.004)], (0.01, 0.003, 0.003)),
            ("geometry and clock", [(1.0, 1.0, 0.0, 0.0), (0.995, 1.0, 0.002, 0.02), (0.993, 1.002, 0.004, -0.02)],
             (0.01, 0.003, 0.003, 0.03)),
            ("geometry and drifting clock", [(1.0, 1.0, 0.0, 0.0, 0.0), (0.995, 1.0, 0.002, 0.05, -1000.0),
                                             (0.993, 1.002, 0.004, 0.02, 1000.0)], (0.01, 0.003, 0.003, 0.03, 1000.0))):
        fits = []
        for start in starts:
            p, _ = nelder_mead(worst, start, steps, iterations=200)
            fits.append(nelder_mead(worst, p, tuple(s / 3 for s in steps), iterations=200))
        p, value = min(fits, key=lambda fit: fit[1])
        clock = f", clock {1000 * p[3]:+.0f} ms" if len(p) > 3 else ""
        clock += f" drifting {p[4]:+.0f} ppm" if len(p) > 4 else ""
        print(f"best common {label}: scale {p[0]:.4f}, R/L {p[1]:.4f}, track {1000 * p[2]:+.1f} mm{clock}: "
              f"largest ratio {value:.2f}")
        print("  " + ", ".join(f"{name} {r:.2f}" for name, r in ratios(p).items()))


def local_clock(runs, p, stretch_s=15.0, step_s=7.5):
    """Prints, per run, the best clock shift [ms] of each stretch, at its start [s]."""
    for name, run in runs.items():
        t, shifts = run["t"], []
        start = t[0]
        while start + stretch_s <= t[-1]:
            a, b = bisect.bisect_left(t, start), bisect.bisect_right(t, start + stretch_s)
            part = {k: v[a:b] for k, v in run.items()}
            best = min(range(-60, 161, 10),
                       key=lambda ms: drift(part, (*p, ms / 1000), window_s=5.0, align_s=1.0))
            shifts.append(f"{start - t[0]:.0f} s: {best:+d}")
            start += step_s
        print(f"{name}: clock shift [ms] by stretch: {', '.join(shifts)}")


def show_patch(runs, p):
    """Prints each run's drift with patch p over its nominal drift."""
    for name, run in runs.items():
        d0, d = drift(run, (1.0, 1.0, 0.0)), drift(run, p)
        print(f"{name}: {1000 * d0:.1f} -> {1000 * d:.1f} mm ({d / d0:.2f})")


def main(argv):
    clock_geometry = patch = None
    if len(argv) > 2 and argv[1] in ("--local-clock", "--patch"):
        try:
            values = tuple(float(v) for v in argv[2].split(","))
        except ValueError:
            values = ()
        sizes, form = ((3,), "SCALE,RATIO,TRACK_ERROR_M") if argv[1] == "--local-clock" else \
            ((3, 4, 5), "SCALE,RATIO,TRACK_ERROR_M[,SHIFT_S[,DRIFT_PPM]]")
        if len(values) not in sizes:
            print(f"optiodom_drift_floor.py: {argv[1]} {argv[2]}: needs {form}", file=sys.stderr)
            return 2
        if argv[1] == "--local-clock":
            clock_geometry = values
        else:
            patch = values
        argv = argv[2:]
    if len(argv) > 1 and argv[1] == "--best-common":
        argv = argv[1:]
        common = True
    else:
        common = False
    if len(argv) < 3 or argv[1] in ("-h", "--help"):
        print(__doc__, file=sys.stderr if len(argv) < 3 else sys.stdout)
        return 0 if len(argv) > 1 and argv[1] in ("-h", "--help") else 2
    data = pathlib.Path(argv[1])
    runs = {}
    training = argv[2].split(",")
    for name in training + argv[3:]:
        path = data / name / f"{pathlib.Path(name).name}_run-01.csv"
        if not path.is_file():
            print(f"optiodom_drift_floor.py: {path}: no such run", file=sys.stderr)
            return 2
        runs[name] = load(path)
    if common:
        best_common(runs)
        return 0
    if clock_geometry:
        local_clock(runs, clock_geometry)
        return 0
    if patch:
        show_patch(runs, patch)
        return 0
    nominal = (1.0, 1.0, 0.0)
    oracles = {name: nelder_mead(lambda p, run=run: drift(run, p), nominal, (0.01, 0.003, 0.003))
               for name, run in runs.items()}
    clocked = {name: nelder_mead(lambda p, run=run: drift(run, p), (*oracles[name][0], 0.0),
                                 (0.01, 0.003, 0.003, 0.03)) for name, run in runs.items()}
    if len(training) == 1:
        carried = oracles[training[0]][0]
    else:
        nominal_drift = {name: drift(runs[name], nominal) for name in training}
        carried = nelder_mead(lambda p: sum(drift(runs[n], p) / nominal_drift[n] for n in training) / len(training),
                              nominal, (0.01, 0.003, 0.003))[0]
    print(f"geometry fitted on {', '.join(training)}'s windows: scale {carried[0]:.4f}, R/L {carried[1]:.4f}, "
          f"track {1000 * carried[2]:+.1f} mm")
    print("| run | nominal 10 s drift | own fit: scale, R/L, track -> drift (ratio) | own fit with a clock shift "
          "(ratio) | training run's fit carried over (ratio) | straight: distance ratio | arcs: heading ratio | in-place turns: heading ratio |")
    print("|---|---|---|---|---|---|---|---|")
    for name, run in runs.items():
        d0 = drift(run, nominal)
        (scale, ratio, track), own = oracles[name]
        over = drift(run, carried)
        shift_s, with_shift = clocked[name][0][3], clocked[name][1]
        straight, arcs, turns = motion_ratios(run)
        print(f"| {name} | {1000 * d0:.1f} mm | {scale:.4f}, {ratio:.4f}, {1000 * track:+.1f} mm -> "
              f"{1000 * own:.1f} mm ({own / d0:.2f}) | {1000 * shift_s:+.0f} ms: {1000 * with_shift:.1f} mm "
              f"({with_shift / d0:.2f}) | {1000 * over:.1f} mm ({over / d0:.2f}) | {straight:.4f} | "
              f"{arcs:.4f} | {turns:.4f} |")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
