#include "gap/internal/twin_residuals.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "estimator/models/enu.h"
#include "gap/locate.h"

namespace roamlab::gap::internal {
namespace {

using recording::Stream;
using recording::StreamType;

double Noise(const recording::StreamInfo& info, const std::string& key) {
  const auto it = info.noise.find(key);
  return it != info.noise.end() ? it->second : 0.0;
}

// Whitened residuals of one series: sums of squares per component, and their 1 s means (WindowMeans, as StreamFits).
struct Accumulator {
  explicit Accumulator(int components) : sum_squares(static_cast<std::size_t>(components), 0.0) {}

  void Add(Time t, const Eigen::VectorXd& whitened) {
    for (int k = 0; k < whitened.size(); ++k) sum_squares[static_cast<std::size_t>(k)] += whitened[k] * whitened[k];
    ++samples;
    windows.Add(t, whitened);
  }

  SimulatedStreamFit Fit() const {
    SimulatedStreamFit f;
    f.samples = samples;
    double total = 0.0;
    for (double s : sum_squares) {
      f.component_rms.push_back(samples > 0 ? std::sqrt(s / samples) : 0.0);
      total += s;
    }
    const double count = static_cast<double>(samples) * static_cast<double>(sum_squares.size());
    f.rms = count > 0.0 ? std::sqrt(total / count) : 0.0;
    f.rms_1s = windows.Rms();
    return f;
  }

  std::vector<double> sum_squares;
  int samples = 0;
  WindowMeans windows;
};

// The series of one stream over [from, to]: an imu's columns as two series.
void AddSeries(const Stream& s, const std::vector<double>& sigma, Time from, Time to, Layout* layout) {
  std::vector<std::size_t> rows;
  std::vector<Time> t;
  for (std::size_t i = 0; i < s.t.size(); ++i) {
    if (s.t[i] < from || to < s.t[i]) continue;
    rows.push_back(i);
    t.push_back(s.t[i]);
  }
  const auto add = [&](const std::string& name, int first, int n) {
    Series series;
    series.name = name;
    series.stream = s.info.name;
    series.type = s.info.type;
    series.first_column = first;
    series.sigma.assign(sigma.begin() + first, sigma.begin() + first + n);
    series.rows = rows;
    series.t = t;
    series.offset = layout->size;
    layout->size += series.size();
    layout->series.push_back(std::move(series));
  };
  if (s.info.type == StreamType::kImu) {
    add("gyroscope", 0, 3);
    add("accelerometer", 3, 3);
  } else {
    add(s.info.name, 0, static_cast<int>(sigma.size()));
  }
}

}  // namespace

std::vector<double> ColumnSigmas(const recording::StreamInfo& info) {
  const auto repeat = [](double sigma, int n) { return std::vector<double>(static_cast<std::size_t>(n), sigma); };
  switch (info.type) {
    case StreamType::kImu: {
      std::vector<double> s = repeat(Noise(info, "gyro_sigma_radps"), 3);
      const std::vector<double> a = repeat(Noise(info, "accel_sigma_mps2"), 3);
      s.insert(s.end(), a.begin(), a.end());
      return s;
    }
    case StreamType::kGps:
    case StreamType::kPosition:
      return repeat(Noise(info, "sigma_m"), 3);
    case StreamType::kPose:
      // x and y only: the height of a pose is that of the stream's reference point, which motion capture of a planar
      // robot does not state (an imported OptiOdom run writes 0).
      return repeat(Noise(info, "position_m") > 0.0 ? Noise(info, "position_m") : Noise(info, "sigma_m"), 2);
    case StreamType::kOdometry:
    case StreamType::kVisualOdometry:
    case StreamType::kScanMatching: {
      std::vector<double> s = repeat(Noise(info, "sigma_mps"), 3);
      const std::vector<double> w = repeat(Noise(info, "sigma_radps"), 3);
      s.insert(s.end(), w.begin(), w.end());
      return s;
    }
    case StreamType::kWheelEncoders: {
      const int n = static_cast<int>(info.columns.size());
      const auto ticks = info.attributes.find("ticks_per_revolution");
      if (info.units == "rad" && ticks != info.attributes.end() && ticks->second > 0.0)
        return repeat(2.0 * M_PI / ticks->second / std::sqrt(12.0), n);
      for (const char* key : {"sigma_mps", "sigma_radps", "sigma_rad"})
        if (Noise(info, key) > 0.0) return repeat(Noise(info, key), n);
      return {};
    }
    case StreamType::kCamera:
    case StreamType::kInputs:
    case StreamType::kLaserScan:
      return {};
    default:
      // One stated sigma for every column (gyroscope, accelerometer, magnetometer, steering).
      if (info.noise.size() != 1) return {};
      return repeat(info.noise.begin()->second, static_cast<int>(info.columns.size()));
  }
}

Layout MakeLayout(const recording::Recording& real, Time from, Time to) {
  Layout layout;
  layout.origin = real.origin;
  for (const Stream& s : real.streams) {
    const std::vector<double> sigma = ColumnSigmas(s.info);
    const bool stated = !sigma.empty() && std::all_of(sigma.begin(), sigma.end(), [](double x) { return x > 0.0; });
    std::string why;
    if (!stated)
      why = "no stated noise";
    else if (static_cast<int>(s.info.columns.size()) < static_cast<int>(sigma.size()))
      why = "fewer columns than its type has";
    else if (s.info.type == StreamType::kGps && !real.origin)
      why = "no origin";
    if (!why.empty()) {
      layout.left_out.push_back(s.info.name + ": " + why);
      continue;
    }
    AddSeries(s, sigma, from, to, &layout);
  }
  return layout;
}

Eigen::VectorXd WhitenedResiduals(const Layout& layout, const recording::Recording& real,
                                  const recording::Recording& twin, std::vector<std::string>* missing) {
  Eigen::VectorXd out = Eigen::VectorXd::Constant(layout.size, std::numeric_limits<double>::quiet_NaN());
  std::optional<estimator::EnuConverter> enu;
  if (layout.origin) enu.emplace(*layout.origin);
  for (const Series& series : layout.series) {
    const Stream* r = real.Find(series.stream);
    const Stream* s = twin.Find(series.stream);
    const int n = series.components();
    if (!r || !s || s->info.type != series.type || s->values.cols() < series.first_column + n) {
      if (missing) missing->push_back(series.name + ": not in the twin");
      continue;
    }
    const auto value = [&](const Stream& stream, std::size_t row) {
      const Eigen::Index k = static_cast<Eigen::Index>(row);
      if (series.type == StreamType::kGps) {
        const Eigen::Vector3d p = stream.values.row(k).head(3).transpose();
        return Eigen::VectorXd(enu->ToEnu(p[0], p[1], p[2]));
      }
      return Eigen::VectorXd(stream.values.row(k).segment(series.first_column, n).transpose());
    };
    std::size_t j = 0;
    for (std::size_t i = 0; i < series.rows.size(); ++i) {
      const Time t = series.t[i];
      while (j < s->t.size() && s->t[j] < t) ++j;
      if (j == s->t.size()) break;
      if (s->t[j] != t) continue;
      const Eigen::VectorXd d = value(*r, series.rows[i]) - value(*s, j);
      for (int c = 0; c < n; ++c)
        out[series.offset + static_cast<Eigen::Index>(i) * n + c] = d[c] / series.sigma[static_cast<std::size_t>(c)];
    }
  }
  return out;
}

std::map<std::string, SimulatedStreamFit> SeriesFits(const Layout& layout, const Eigen::VectorXd& whitened) {
  std::map<std::string, SimulatedStreamFit> out;
  for (const Series& series : layout.series) {
    const int n = series.components();
    Accumulator a(n);
    for (std::size_t i = 0; i < series.rows.size(); ++i) {
      const Eigen::VectorXd w = whitened.segment(series.offset + static_cast<Eigen::Index>(i) * n, n);
      if (w.allFinite()) a.Add(series.t[i], w);
    }
    if (a.samples > 0) out[series.name] = a.Fit();
  }
  return out;
}

double SumOfSquares(const Eigen::VectorXd& whitened, int* count) {
  double sum = 0.0;
  int n = 0;
  for (Eigen::Index i = 0; i < whitened.size(); ++i) {
    if (!std::isfinite(whitened[i])) continue;
    sum += whitened[i] * whitened[i];
    ++n;
  }
  if (count) *count = n;
  return sum;
}

std::vector<estimator::MeasurementResidual> MeasurementResiduals(const Layout& layout,
                                                                 const Eigen::VectorXd& whitened) {
  std::vector<estimator::MeasurementResidual> out;
  for (const Series& s : layout.series) {
    const int n = s.components();
    for (std::size_t i = 0; i < s.rows.size(); ++i) {
      const Eigen::VectorXd r = whitened.segment(s.offset + static_cast<Eigen::Index>(i) * n, n);
      if (r.allFinite()) out.push_back({s.name, s.t[i], r, true});
    }
  }
  return out;
}

}  // namespace roamlab::gap::internal
