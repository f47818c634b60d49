#include "eval/calibration_consistency.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

#include <Eigen/Cholesky>

#include "common/check.h"
#include "common/json.h"

namespace roamlab::eval {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kZ95 = 1.959963984540054;  // the standard normal's 97.5 % quantile

// P(|x| <= k) for a standard normal x.
double NormalCoverage(int k) { return std::erf(k / std::sqrt(2.0)); }

// e^T C^-1 e, NaN when C is not symmetric positive definite or holds a non-finite entry.
double BlockNees(const Eigen::VectorXd& error, const Eigen::MatrixXd& covariance) {
  if (!error.allFinite() || !covariance.allFinite()) return kNaN;
  const Eigen::LLT<Eigen::MatrixXd> llt(covariance);
  if (llt.info() != Eigen::Success) return kNaN;
  return error.dot(llt.solve(error));
}

// Coverage of k sigma for component i over the runs where its std is finite and positive.
Coverage CoverageOf(const std::vector<ParameterDraw>& draws, Eigen::Index i, int k) {
  Coverage c;
  c.sigmas = k;
  c.nominal = NormalCoverage(k);
  int trials = 0, inside = 0;
  for (const ParameterDraw& d : draws) {
    if (!(std::isfinite(d.std[i]) && d.std[i] > 0.0) || !std::isfinite(d.error[i])) continue;
    ++trials;
    if (std::abs(d.error[i]) <= k * d.std[i]) ++inside;
  }
  if (trials == 0) {
    c.fraction = kNaN;
    c.confidence = {kNaN, kNaN};
    return c;
  }
  c.fraction = static_cast<double>(inside) / trials;
  c.confidence = WilsonInterval(inside, trials);
  return c;
}

// Bias, spread and mean std of component i.
ComponentConsistency Moments(const std::vector<ParameterDraw>& draws, Eigen::Index i) {
  ComponentConsistency c;
  const double n = static_cast<double>(draws.size());
  double sum = 0.0, std_sum = 0.0;
  int std_count = 0;
  for (const ParameterDraw& d : draws) {
    sum += d.error[i];
    if (std::isfinite(d.std[i])) {
      std_sum += d.std[i];
      ++std_count;
    }
  }
  c.bias = sum / n;
  double squares = 0.0;
  for (const ParameterDraw& d : draws) squares += (d.error[i] - c.bias) * (d.error[i] - c.bias);
  c.spread = draws.size() >= 2 ? std::sqrt(squares / (n - 1.0)) : kNaN;
  c.bias_standard_error = c.spread / std::sqrt(n);
  c.biased = std::abs(c.bias) > kBiasStandardErrors * c.bias_standard_error;
  c.mean_std = std_count > 0 ? std_sum / std_count : kNaN;
  c.spread_over_std = c.spread / c.mean_std;
  return c;
}

// The block NEES per run, its mean over the runs where it is defined and the band for that many runs.
void NeesOf(const std::vector<ParameterDraw>& draws, BlockConsistency* block) {
  double sum = 0.0;
  for (const ParameterDraw& d : draws) {
    block->nees.push_back(BlockNees(d.error, d.covariance));
    if (std::isfinite(block->nees.back())) {
      sum += block->nees.back();
      ++block->nees_runs;
    }
  }
  if (block->nees_runs == 0) {
    block->mean_nees = kNaN;
    block->band = {kNaN, kNaN};
    return;
  }
  block->mean_nees = sum / block->nees_runs;
  block->band = AverageNeesBand(block->nees_runs, block->dimension, block->alpha);
}

nlohmann::json PairJson(const Interval& interval) { return {Number(interval.lo), Number(interval.hi)}; }

nlohmann::json ComponentJson(const ComponentConsistency& c, int index) {
  nlohmann::json coverage = nlohmann::json::array();
  for (const Coverage& k : c.coverage)
    coverage.push_back({{"sigmas", k.sigmas},
                        {"nominal", k.nominal},
                        {"fraction", Number(k.fraction)},
                        {"confidence", PairJson(k.confidence)},
                        {"consistent", k.consistent()}});
  return {{"index", index},
          {"bias", Number(c.bias)},
          {"bias_standard_error", Number(c.bias_standard_error)},
          {"biased", c.biased},
          {"spread", Number(c.spread)},
          {"mean_std", Number(c.mean_std)},
          {"spread_over_std", Number(c.spread_over_std)},
          {"coverage", coverage},
          {"cramer_rao_std", Number(c.cramer_rao_std)},
          {"efficiency", Number(c.efficiency)},
          {"noise_free_error", Number(c.noise_free_error)}};
}

std::string Format(const char* format, double x) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, format, x);
  return buffer;
}

// "  95.0" or "   nan" for a percentage.
std::string Percent(double fraction) { return Format("%6.1f", 100.0 * fraction); }

}  // namespace

Interval WilsonInterval(int successes, int trials) {
  ROAMLAB_CHECK(trials >= 1 && successes >= 0 && successes <= trials, "Wilson interval: bad counts");
  const double n = trials, p = successes / n, z2 = kZ95 * kZ95;
  const double centre = (p + z2 / (2.0 * n)) / (1.0 + z2 / n);
  const double half = kZ95 / (1.0 + z2 / n) * std::sqrt(p * (1.0 - p) / n + z2 / (4.0 * n * n));
  return {std::max(0.0, centre - half), std::min(1.0, centre + half)};
}

BlockConsistency BlockStatistics(const std::string& name, const std::vector<ParameterDraw>& draws,
                                 const Eigen::VectorXd& cramer_rao_std, double alpha) {
  ROAMLAB_CHECK(!draws.empty(), "consistency: no draws of " + name);
  ROAMLAB_CHECK(alpha > 0.0 && alpha < 1.0, "consistency: alpha outside (0, 1)");
  const Eigen::Index d = draws.front().error.size();
  ROAMLAB_CHECK(d >= 1, "consistency: empty block " + name);
  for (const ParameterDraw& draw : draws)
    ROAMLAB_CHECK(draw.error.size() == d && draw.std.size() == d && draw.covariance.rows() == d &&
                      draw.covariance.cols() == d,
                  "consistency: draws of " + name + " differ in size");
  ROAMLAB_CHECK(cramer_rao_std.size() == 0 || cramer_rao_std.size() == d,
                "consistency: Cramer-Rao std of " + name + " of the wrong size");
  BlockConsistency block;
  block.name = name;
  block.runs = static_cast<int>(draws.size());
  block.dimension = static_cast<int>(d);
  block.alpha = alpha;
  for (Eigen::Index i = 0; i < d; ++i) {
    ComponentConsistency c = Moments(draws, i);
    for (int k = 1; k <= 3; ++k) c.coverage[k - 1] = CoverageOf(draws, i, k);
    c.cramer_rao_std = cramer_rao_std.size() == d ? cramer_rao_std[i] : kNaN;
    c.efficiency = c.mean_std / c.cramer_rao_std;
    block.components.push_back(c);
  }
  NeesOf(draws, &block);
  return block;
}

nlohmann::json ConsistencyJson(const std::vector<BlockConsistency>& blocks) {
  nlohmann::json out = nlohmann::json::array();
  for (const BlockConsistency& b : blocks) {
    nlohmann::json components = nlohmann::json::array();
    for (std::size_t i = 0; i < b.components.size(); ++i)
      components.push_back(ComponentJson(b.components[i], static_cast<int>(i)));
    out.push_back({{"name", b.name},
                   {"runs", b.runs},
                   {"dimension", b.dimension},
                   {"nees",
                    {{"mean", Number(b.mean_nees)},
                     {"band", PairJson(b.band)},
                     {"alpha", b.alpha},
                     {"in_band", b.nees_in_band()},
                     {"runs", b.nees_runs},
                     {"per_run", NumberArray(b.nees)}}},
                   {"components", components}});
  }
  return out;
}

std::string ConsistencyTable(const std::vector<BlockConsistency>& blocks) {
  std::ostringstream s;
  if (blocks.empty()) return "";
  char header[192];
  std::snprintf(header, sizeof header, "%-23s%24s%10s%12s%11s %6s%6s%6s%12s%9s%14s\n", "parameter",
                "bias +- std error  ", "spread", "mean std", "spread/std", "1s %", "2s %", "3s %", "CRB std", "std/CRB",
                "no-noise err");
  s << header;
  for (const BlockConsistency& b : blocks)
    for (std::size_t i = 0; i < b.components.size(); ++i) {
      const ComponentConsistency& c = b.components[i];
      char label[96];
      std::snprintf(label, sizeof label, "%s[%zu]", b.name.c_str(), i);
      char padded[128];
      std::snprintf(padded, sizeof padded, "%-22s ", label);
      s << padded
        << Format("%+10.3e", c.bias) << " +- " << Format("%9.3e", c.bias_standard_error) << (c.biased ? "*" : " ")
        << Format("%10.3e", c.spread) << Format("%12.3e", c.mean_std) << Format("%10.2f", c.spread_over_std) << "  "
        << Percent(c.coverage[0].fraction) << Percent(c.coverage[1].fraction) << Percent(c.coverage[2].fraction)
        << Format("%12.3e", c.cramer_rao_std) << Format("%9.2f", c.efficiency)
        << Format("%+14.3e", c.noise_free_error) << "\n";
    }
  s << "block                  dim  runs  mean NEES  band (" << Format("%.0f", 100.0 * (1.0 - blocks.front().alpha))
    << " %)\n";
  for (const BlockConsistency& b : blocks) {
    char row[160];
    std::snprintf(row, sizeof row, "%-22s %3d %5d %10.3f  [%.3f, %.3f]%s\n", b.name.c_str(), b.dimension, b.nees_runs,
                  b.mean_nees, b.band.lo, b.band.hi, b.nees_in_band() ? "" : "  outside");
    s << row;
  }
  s << "(* bias beyond " << Format("%.0f", kBiasStandardErrors) << " standard errors; coverage in %)\n";
  return s.str();
}

}  // namespace roamlab::eval
