#include "eval/nees.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <sstream>
#include <string_view>

#include "common/check.h"
#include "common/json.h"

namespace roamlab::eval {
namespace {

constexpr const char* kCovarianceHeader = "t,xx,xy,xz,yx,yy,yz,zx,zy,zz";

std::string_view Trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

std::vector<std::string_view> SplitCommas(std::string_view line) {
  std::vector<std::string_view> fields;
  std::size_t begin = 0;
  while (true) {
    const std::size_t comma = line.find(',', begin);
    fields.push_back(
        Trim(line.substr(begin, comma == std::string_view::npos ? std::string_view::npos : comma - begin)));
    if (comma == std::string_view::npos) break;
    begin = comma + 1;
  }
  return fields;
}

// A finite number filling the whole field.
bool ParseFinite(std::string_view field, double* value) {
  const std::string text(field);
  if (text.empty()) return false;
  char* end = nullptr;
  *value = std::strtod(text.c_str(), &end);
  return end == text.c_str() + text.size() && std::isfinite(*value);
}

// One data row; `where` is "<path>:<line>".
Status ParseCovarianceRow(std::string_view line, const std::string& where, StampedCovariance* row) {
  const std::vector<std::string_view> fields = SplitCommas(line);
  if (fields.size() != 10) return Status::Error(where + ": expected 10 fields, found " + std::to_string(fields.size()));
  const std::optional<Time> t = ParseSeconds(fields[0]);
  if (!t) return Status::Error(where + ": field 't': not a time '" + std::string(fields[0]) + "'");
  row->t = *t;
  static const char* kNames[9] = {"xx", "xy", "xz", "yx", "yy", "yz", "zx", "zy", "zz"};
  for (int k = 0; k < 9; ++k) {
    double v = 0.0;
    if (!ParseFinite(fields[k + 1], &v))
      return Status::Error(where + ": field '" + kNames[k] + "': not a finite number '" + std::string(fields[k + 1]) +
                           "'");
    row->covariance_world(k / 3, k % 3) = v;
  }
  // Symmetric up to rounding; stored symmetrized.
  const Eigen::Matrix3d& c = row->covariance_world;
  const double scale = std::max(c.cwiseAbs().maxCoeff(), std::numeric_limits<double>::min());
  if ((c - c.transpose()).cwiseAbs().maxCoeff() > 1e-6 * scale)
    return Status::Error(where + ": covariance is not symmetric");
  row->covariance_world = 0.5 * (c + c.transpose()).eval();
  return Status::Ok();
}

}  // namespace

double PositionNees(const Eigen::Vector3d& error, const Eigen::Matrix3d& covariance) {
  const Eigen::LLT<Eigen::Matrix3d> llt(covariance);
  if (llt.info() != Eigen::Success || !covariance.isApprox(covariance.transpose(), 1e-9))
    return std::numeric_limits<double>::quiet_NaN();
  // |L^-1 e|^2 = e^T (L L^T)^-1 e.
  return llt.matrixL().solve(error).squaredNorm();
}

Result<std::vector<StampedCovariance>> ReadPositionCovariances(const std::string& path) {
  std::ifstream in(path);
  if (!in) return Status::Error(path + ": cannot open file");
  std::string line;
  if (!std::getline(in, line))
    return Status::Error(path + ":1: empty file, expected header '" + std::string(kCovarianceHeader) + "'");
  if (Trim(line) != kCovarianceHeader)
    return Status::Error(path + ":1: header must be '" + std::string(kCovarianceHeader) + "'");
  std::vector<StampedCovariance> rows;
  int line_number = 1;
  while (std::getline(in, line)) {
    ++line_number;
    if (Trim(line).empty()) continue;
    const std::string where = path + ":" + std::to_string(line_number);
    StampedCovariance row;
    if (Status status = ParseCovarianceRow(line, where, &row); !status.ok()) return status;
    if (!rows.empty() && !(rows.back().t < row.t)) return Status::Error(where + ": timestamp not increasing");
    rows.push_back(row);
  }
  return rows;
}

double FractionInBand(const std::vector<Time>& t, const std::vector<double>& values, Interval band, double t0_s) {
  ROAMLAB_CHECK(t.size() == values.size(),
                "FractionInBand: " << t.size() << " times vs " << values.size() << " values");
  std::size_t counted = 0;
  std::size_t inside = 0;
  for (std::size_t k = 0; k < t.size(); ++k) {
    if (SecondsBetween(t.front(), t[k]) < t0_s) continue;
    ++counted;
    if (values[k] >= band.lo && values[k] <= band.hi) ++inside;
  }
  if (counted == 0) return std::numeric_limits<double>::quiet_NaN();
  return static_cast<double>(inside) / static_cast<double>(counted);
}

MonteCarloNees AggregateNees(const std::vector<Time>& t, const std::vector<std::vector<double>>& runs, int dof,
                             double t0_s, double alpha) {
  ROAMLAB_CHECK(!runs.empty(), "AggregateNees needs at least one run");
  ROAMLAB_CHECK(dof >= 1, "dof must be >= 1, got " << dof);
  ROAMLAB_CHECK(alpha > 0.0 && alpha < 1.0, "alpha must be in (0, 1), got " << alpha);
  ROAMLAB_CHECK(t0_s >= 0.0, "t0_s must be >= 0, got " << t0_s);
  for (std::size_t k = 1; k < t.size(); ++k) ROAMLAB_CHECK(t[k - 1] < t[k], "time grid not strictly increasing");
  MonteCarloNees nees;
  nees.runs = static_cast<int>(runs.size());
  nees.dof = dof;
  nees.alpha = alpha;
  nees.t0_s = t0_s;
  nees.band = AverageNeesBand(nees.runs, dof, alpha);
  nees.t = t;
  // Mean over runs at each grid time.
  nees.mean_nees.assign(t.size(), 0.0);
  for (std::size_t j = 0; j < runs.size(); ++j) {
    ROAMLAB_CHECK(runs[j].size() == t.size(), "run " << j << " has " << runs[j].size() << " values, grid " << t.size());
    for (std::size_t k = 0; k < t.size(); ++k) {
      ROAMLAB_CHECK(!std::isnan(runs[j][k]), "run " << j << " has a NaN NEES at step " << k);
      nees.mean_nees[k] += runs[j][k];
    }
  }
  for (double& m : nees.mean_nees) m /= static_cast<double>(runs.size());
  nees.fraction_in_band =
      t.empty() ? std::numeric_limits<double>::quiet_NaN() : FractionInBand(t, nees.mean_nees, nees.band, t0_s);
  return nees;
}

nlohmann::json NeesJson(const MonteCarloNees& nees) {
  nlohmann::json t = nlohmann::json::array();
  for (Time time : nees.t) t.push_back(time.seconds());
  nlohmann::json mean = nlohmann::json::array();
  for (double m : nees.mean_nees) mean.push_back(Number(m));
  return {{"runs", nees.runs},
          {"dof", nees.dof},
          {"band", {nees.band.lo, nees.band.hi}},
          {"alpha", nees.alpha},
          {"t0_s", nees.t0_s},
          {"t", t},
          {"mean_nees", mean},
          {"fraction_in_band", Number(nees.fraction_in_band)}};
}

}  // namespace roamlab::eval
