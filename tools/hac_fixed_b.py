#!/usr/bin/env python3
"""How far the twin's HAC std is from honest when its lag is a fixed share of the series (fixed-b).

The twin's HAC (estimator/covariance.h PrewhitenedBartlettSum, gap/twin.h) takes the Bartlett sum of the scores
prewhitened by an AR(1) to the lag L of AnalyzeAutocorrelation, which is capped at a quarter of the series; on the
OptiOdom runs the motion capture's lag is at that cap (b = L / n = 1/4). With b fixed the HAC variance is not
consistent (Kiefer and Vogelsang 2005): it stays random and low, and the t statistic is not normal. This Monte-Carlo
measures it on the simplest fit, the mean of n samples of a Gaussian AR(1) series of coefficient phi (its score at the
fit x_t - mean, summing to zero as a fit's scores do), with the twin's estimator at L = n / 4:
  E[M] / LRV:  the HAC long-run sum over the true one, n / (1 - phi)^2;
  |t| q95:     the 95 % quantile of |mean| / HAC std (1.96 if the std were exact);
  P(|t| > 2):  how often the 2-std interval misses (0.046 if exact);
  pair q95, P(pair > 2): the same for two independent runs, |a - b| / sqrt(sa^2 + sb^2), the within-day spread.

    python3 tools/hac_fixed_b.py [N] [REPLICATIONS]   (defaults 925, the stamps of a Dec square run's training part,
                                                       and 2000; seed fixed)

With --grid it prints, for lags L = b n over a grid of b, the 95 % quantile of |t| for phi 0, 0.5 and 0.9 beside
Kiefer and Vogelsang's fixed-b critical value of the Bartlett kernel, cv(b) = 1.96 + 2.9694 b + 0.4160 b^2 -
0.5324 b^3 (two-sided 5 %), whose ratio to 1.96 the twin's HAC std is widened by (gap/twin_compare.cc FixedBFactor).

    python3 tools/hac_fixed_b.py --grid [N] [REPLICATIONS]
"""
import math
import random
import sys

MAX_PREWHITENING = 0.97  # as estimator/covariance.cc


def bartlett_sum(a, lag):
    """sum_{|l| <= L} (1 - |l| / (L + 1)) sum_t a_t a_{t+l}, by the box sums of estimator/covariance.cc BartlettSum."""
    n = len(a)
    boxes = n + lag
    box = [0.0] * boxes
    running = 0.0
    for t in range(boxes):
        if t < n:
            running += a[t]
        if 0 <= t - lag - 1 < n:
            running -= a[t - lag - 1]
        box[t] = running
    total = 0.0
    running = 0.0
    for t in range(boxes - 1, -1, -1):
        running += box[t]
        if t + lag + 1 < boxes:
            running -= box[t + lag + 1]
        if t < n:
            total += a[t] * running / (lag + 1)
    return total


def prewhitened_bartlett_sum(a, lag):
    """estimator/covariance.cc PrewhitenedBartlettSum for one component."""
    n = len(a)
    numerator = sum(a[t] * a[t - 1] for t in range(1, n))
    denominator = sum(a[t - 1] ** 2 for t in range(1, n))
    rho = max(-MAX_PREWHITENING, min(MAX_PREWHITENING, numerator / denominator))
    whitened = [a[t] - rho * a[t - 1] for t in range(1, n)]
    return n / (n - 1) * bartlett_sum(whitened, lag) / (1 - rho) ** 2


def quantile(values, q):
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, int(q * len(ordered)))]


def t_quantile(n, lag, phi, replications, rng):
    """The 95 % quantile of |mean| / HAC std over replications of an AR(1) series of n samples."""
    abs_t = []
    for _ in range(replications):
        x = [rng.gauss(0.0, 1.0) / math.sqrt(1.0 - phi * phi)]
        for _ in range(n - 1):
            x.append(phi * x[-1] + rng.gauss(0.0, 1.0))
        mean = sum(x) / n
        abs_t.append(abs(n * mean / math.sqrt(prewhitened_bartlett_sum([v - mean for v in x], lag))))
    return quantile(abs_t, 0.95)


def grid(n, replications):
    rng = random.Random(7)
    print(f"n {n}, {replications} replications")
    print("| b | L | 95 % quantile of abs(t), AR(1) coefficient 0 | coefficient 0.5 | coefficient 0.9 | cv(b) |")
    print("|---|---|---|---|---|---|")
    for b in (0.02, 0.05, 0.1, 0.15, 0.2, 0.25):
        lag = max(1, round(b * n))
        q = [t_quantile(n, lag, phi, replications, rng) for phi in (0.0, 0.5, 0.9)]
        cv = 1.96 + 2.9694 * b + 0.4160 * b * b - 0.5324 * b ** 3
        print(f"| {b:.2f} | {lag} | {q[0]:.2f} | {q[1]:.2f} | {q[2]:.2f} | {cv:.2f} |", flush=True)
    return 0


def main(n, replications):
    lag = n // 4
    rng = random.Random(7)
    print(f"n {n}, L {lag} (b = {lag / n:.3f}), {replications} replications")
    print("| phi | E[M] / LRV | abs(t) q95 | P(abs(t) > 2) | pair q95 | P(pair > 2) |")
    print("|---|---|---|---|---|---|")
    for phi in (0.0, 0.5, 0.9, 0.98):
        ratios, t, means = [], [], []
        for _ in range(replications):
            x = [rng.gauss(0.0, 1.0) / math.sqrt(1.0 - phi * phi)]
            for _ in range(n - 1):
                x.append(phi * x[-1] + rng.gauss(0.0, 1.0))
            mean = sum(x) / n
            m = prewhitened_bartlett_sum([v - mean for v in x], lag)
            ratios.append(m / (n / (1.0 - phi) ** 2))
            t.append(n * mean / math.sqrt(m))
            means.append(mean)
        abs_t = [abs(v) for v in t]
        pairs = [abs(means[r] - means[r + 1]) / math.hypot(means[r] / t[r], means[r + 1] / t[r + 1])
                 for r in range(0, replications - 1, 2)]
        print(f"| {phi:.2f} | {sum(ratios) / replications:.3f} | {quantile(abs_t, 0.95):.2f} | "
              f"{sum(v > 2.0 for v in abs_t) / replications:.3f} | {quantile(pairs, 0.95):.2f} | "
              f"{sum(v > 2.0 for v in pairs) / len(pairs):.3f} |")
    return 0


if __name__ == "__main__":
    if len(sys.argv) > 1 and sys.argv[1] in ("-h", "--help"):
        print(__doc__)
        sys.exit(0)
    mode = main
    if len(sys.argv) > 1 and sys.argv[1] == "--grid":
        mode = grid
        del sys.argv[1]
    try:
        args = [int(a) for a in sys.argv[1:3]]
    except ValueError:
        print(__doc__, file=sys.stderr)
        sys.exit(2)
    if len(sys.argv) > 3 or any(a < 8 for a in args):
        print(__doc__, file=sys.stderr)
        sys.exit(2)
    sys.exit(mode(*(args + [925, 2000][len(args):])))
