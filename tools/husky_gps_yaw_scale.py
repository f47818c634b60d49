#!/usr/bin/env python3
"""How well a recording's GPS track fixes the yaw-rate scale of its heading sources.

Usage: python3 tools/husky_gps_yaw_scale.py REC [--window S] [--odometry-lag S]

REC is an imported recording with `odometry` (body twist: vx, wz), `imu` and `gps` streams, the Husky's as
docs/results.md imports it. Each heading source's yaw rate [rad/s] (the odometry's wz in the body frame, and the
gyroscope's y axis: the Husky's IMU is mounted a quarter turn about x, so its y axis is the body's vertical; another
mounting needs another column) is multiplied by a scale k and integrated with the odometry's forward speed
times s into a planar track; over consecutive windows of S seconds that track is fitted to the GPS fixes (east,
north) by a rigid planar motion, and the residual's mean square summed over the windows. Printed per source: the
best k (s profiled out), the profile of the residual RMS over k, and a bootstrap over the windows (resampled with
replacement, 500 draws) of the best k: the spread of what the GPS says about the scale, its slow error included.
The odometry's stamps are moved earlier by --odometry-lag (its lag behind the gyroscope, default 0.4 s).
"""
import bisect
import csv
import math
import pathlib
import random
import sys

YAW_SCALES = [0.90 + 0.01 * i for i in range(31)]
SPEED_SCALES = [0.90 + 0.02 * i for i in range(11)]
EARTH_RADIUS_M = 6378137.0


def read_columns(path):
    with open(path, newline='') as f:
        rows = list(csv.DictReader(f))
    if not rows:
        sys.exit(f'{path}: no rows')
    return {key: [float(r[key]) for r in rows] for key in rows[0]}


def interpolate(ts, xs, t):
    i = bisect.bisect_left(ts, t)
    if i <= 0:
        return xs[0]
    if i >= len(ts):
        return xs[-1]
    a = (t - ts[i - 1]) / (ts[i] - ts[i - 1])
    return xs[i - 1] + a * (xs[i] - xs[i - 1])


def integrate(ts, speed_mps, yaw_rate_radps):
    """Planar track of a forward speed and a yaw rate (Euler steps), from the origin heading east."""
    x, y, psi = [0.0], [0.0], 0.0
    for i in range(1, len(ts)):
        dt = ts[i] - ts[i - 1]
        psi += yaw_rate_radps[i] * dt
        x.append(x[-1] + speed_mps[i] * math.cos(psi) * dt)
        y.append(y[-1] + speed_mps[i] * math.sin(psi) * dt)
    return x, y


def rigid_fit_mean_square(p, q):
    """Mean squared residual of the planar points p after the rigid motion that best maps them onto q."""
    n = len(p)
    pcx, pcy = sum(a for a, _ in p) / n, sum(b for _, b in p) / n
    qcx, qcy = sum(a for a, _ in q) / n, sum(b for _, b in q) / n
    sxx = sxy = 0.0
    spp = sqq = 0.0
    for (a, b), (c, d) in zip(p, q):
        a, b, c, d = a - pcx, b - pcy, c - qcx, d - qcy
        sxx += a * c + b * d
        sxy += a * d - b * c
        spp += a * a + b * b
        sqq += c * c + d * d
    return max(spp + sqq - 2.0 * math.hypot(sxx, sxy), 0.0) / n


def window_mean_squares(track_t, track_x, track_y, gps_t, gps_en, window_s):
    first, last = track_t[0] + 1.0, track_t[-1] - 1.0
    kept = [i for i, t in enumerate(gps_t) if first < t < last]
    out, start = [], gps_t[kept[0]]
    while start + window_s <= gps_t[kept[-1]]:
        idx = [i for i in kept if start <= gps_t[i] < start + window_s]
        p = [(interpolate(track_t, track_x, gps_t[i]), interpolate(track_t, track_y, gps_t[i])) for i in idx]
        out.append(rigid_fit_mean_square(p, [gps_en[i] for i in idx]))
        start += window_s
    return out


def main(argv):
    if not argv or argv[0].startswith('-'):
        sys.exit(__doc__)
    rec = pathlib.Path(argv[0])
    window_s = float(argv[argv.index('--window') + 1]) if '--window' in argv else 60.0
    lag_s = float(argv[argv.index('--odometry-lag') + 1]) if '--odometry-lag' in argv else 0.4
    odo, imu, gps = (read_columns(rec / f'{name}.csv') for name in ('odometry', 'imu', 'gps'))
    lat0, lon0 = math.radians(gps['latitude'][0]), math.radians(gps['longitude'][0])
    gps_en = [(EARTH_RADIUS_M * math.cos(lat0) * (math.radians(lon) - lon0), EARTH_RADIUS_M * (math.radians(lat) - lat0))
              for lat, lon in zip(gps['latitude'], gps['longitude'])]
    # The Husky's IMU is mounted a quarter turn about x: its y axis is the body's vertical.
    gyro_yaw = [interpolate(imu['t'], imu['wy'], t) for t in odo['t']]
    sources = {'odometry': ([t - lag_s for t in odo['t']], odo['wz']), 'gyroscope': (odo['t'], gyro_yaw)}
    for name, (ts, yaw_rate) in sources.items():
        table = {}
        for k in YAW_SCALES:
            for s in SPEED_SCALES:
                x, y = integrate(ts, [s * v for v in odo['vx']], [k * w for w in yaw_rate])
                table[(k, s)] = window_mean_squares(ts, x, y, gps['t'], gps_en, window_s)
        n = len(next(iter(table.values())))
        total = {key: sum(v) / n for key, v in table.items()}
        best = min(total, key=total.get)
        profile = {k: min(total[(k, s)] for s in SPEED_SCALES) for k in YAW_SCALES}
        print(f'{name}: {window_s:g} s windows ({n}), best yaw scale {best[0]:.2f} (speed scale {best[1]:.2f}), '
              f'GPS residual {math.sqrt(total[best]):.3f} m')
        print('  residual RMS over the yaw scale: ' +
              ', '.join(f'{k:.2f} {math.sqrt(profile[k]):.3f}' for k in YAW_SCALES[::2]))
        rng = random.Random(1)
        draws = []
        for _ in range(500):
            pick = [rng.randrange(n) for _ in range(n)]
            draws.append(min(table, key=lambda key: sum(table[key][j] for j in pick))[0])
        draws.sort()
        mean = sum(draws) / len(draws)
        std = math.sqrt(sum((d - mean) ** 2 for d in draws) / len(draws))
        print(f'  bootstrap over the windows: {mean:.3f} +- {std:.3f} (95 %: {draws[12]:.2f} to {draws[487]:.2f})')


if __name__ == '__main__':
    main(sys.argv[1:])
