#include "sim/faults.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <sstream>

namespace roamlab::sim {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kWgs84A = 6378137.0;              // semi-major axis [m]
constexpr double kWgs84E2 = 6.69437999014e-3;      // first eccentricity squared
constexpr std::uint32_t kFirstFaultSource = 1000;  // above every NoiseSource (sim/noise.h)

// A generator of its own for fault `index` (the scheme of sim/noise.h, with sources from kFirstFaultSource).
std::mt19937_64 FaultGenerator(std::uint64_t seed, std::size_t index) {
  std::seed_seq sequence{static_cast<std::uint32_t>(seed), static_cast<std::uint32_t>(seed >> 32),
                         kFirstFaultSource + static_cast<std::uint32_t>(index)};
  return std::mt19937_64(sequence);
}

// The stream's rows `keep` (in order, an index may repeat), everything else unchanged.
void SelectRows(const std::vector<Eigen::Index>& keep, recording::Stream* s) {
  std::vector<Time> t;
  Eigen::MatrixXd values(static_cast<Eigen::Index>(keep.size()), s->values.cols());
  std::vector<std::string> text;
  for (std::size_t i = 0; i < keep.size(); ++i) {
    const Eigen::Index row = keep[i];
    t.push_back(s->t[static_cast<std::size_t>(row)]);
    values.row(static_cast<Eigen::Index>(i)) = s->values.row(row);
    if (!s->text.empty()) text.push_back(s->text[static_cast<std::size_t>(row)]);
  }
  s->t = std::move(t);
  s->values = std::move(values);
  if (!s->text.empty()) s->text = std::move(text);
}

bool InWindow(Time t, double start_s, double duration_s) {
  const double s = t.seconds();
  return s >= start_s && s < start_s + duration_s;
}

// Row `r` of a gps stream [latitude_deg, longitude_deg, altitude_m] moved by `offset_m` (east, north, up).
void MoveFix(const Eigen::Vector3d& offset_m, Eigen::Index r, Eigen::MatrixXd* values) {
  auto row = values->row(r);
  const double latitude = row(0) * kPi / 180.0;
  const double w = std::sqrt(1.0 - kWgs84E2 * std::sin(latitude) * std::sin(latitude));
  const double meridian_m = kWgs84A * (1.0 - kWgs84E2) / (w * w * w);
  const double normal_m = kWgs84A / w;
  row(0) += offset_m.y() / meridian_m * 180.0 / kPi;
  row(1) += offset_m.x() / (normal_m * std::cos(latitude)) * 180.0 / kPi;
  row(2) += offset_m.z();
}

int Outliers(const FaultOptions& f, std::mt19937_64& rng, recording::Stream* s) {
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  std::normal_distribution<double> normal(0.0, 1.0);
  int moved = 0;
  for (Eigen::Index row = 0; row < s->values.rows(); ++row) {
    if (!(uniform(rng) < f.fraction)) continue;
    ++moved;
    if (s->info.type == recording::StreamType::kGps) {
      Eigen::Vector3d direction(normal(rng), normal(rng), normal(rng));
      if (direction.norm() == 0.0) direction = Eigen::Vector3d::UnitX();
      MoveFix(f.size * direction.normalized(), row, &s->values);
      continue;
    }
    for (Eigen::Index c = 0; c < s->values.cols(); ++c) s->values(row, c) += uniform(rng) < 0.5 ? -f.size : f.size;
  }
  return moved;
}

int Outage(const FaultOptions& f, recording::Stream* s) {
  std::vector<Eigen::Index> keep;
  for (std::size_t i = 0; i < s->t.size(); ++i)
    if (!InWindow(s->t[i], f.start_s, f.duration_s)) keep.push_back(static_cast<Eigen::Index>(i));
  const int removed = static_cast<int>(s->t.size() - keep.size());
  SelectRows(keep, s);
  return removed;
}

int ClockJump(const FaultOptions& f, recording::Stream* s) {
  const std::int64_t jump_ns = Time::FromSeconds(f.jump_s).nanoseconds();
  int moved = 0;
  for (Time& t : s->t) {
    if (t.seconds() < f.at_s) continue;
    t = Time::FromNanoseconds(t.nanoseconds() + jump_ns);
    ++moved;
  }
  return moved;
}

int Duplicates(const FaultOptions& f, std::mt19937_64& rng, recording::Stream* s) {
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  std::vector<Eigen::Index> keep;
  for (std::size_t i = 0; i < s->t.size(); ++i) {
    keep.push_back(static_cast<Eigen::Index>(i));
    if (uniform(rng) < f.fraction) keep.push_back(static_cast<Eigen::Index>(i));
  }
  const int copies = static_cast<int>(keep.size() - s->t.size());
  SelectRows(keep, s);
  return copies;
}

int Freeze(const FaultOptions& f, recording::Stream* s) {
  std::optional<Eigen::Index> first;
  int frozen = 0;
  for (std::size_t i = 0; i < s->t.size(); ++i) {
    if (!InWindow(s->t[i], f.start_s, f.duration_s)) continue;
    const Eigen::Index row = static_cast<Eigen::Index>(i);
    if (!first) {
      first = row;
      continue;
    }
    s->values.row(row) = s->values.row(*first);
    if (!s->text.empty()) s->text[i] = s->text[static_cast<std::size_t>(*first)];
    ++frozen;
  }
  return frozen;
}

std::string NumberText(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

}  // namespace

const std::vector<std::string>& FaultKeys(const std::string& type) {
  static const std::map<std::string, std::vector<std::string>> keys = {
      {"outliers", {"fraction", "size"}}, {"outage", {"start_s", "duration_s"}}, {"clock_jump", {"at_s", "jump_s"}},
      {"duplicates", {"fraction"}},       {"freeze", {"start_s", "duration_s"}},
  };
  static const std::vector<std::string> none;
  const auto it = keys.find(type);
  return it == keys.end() ? none : it->second;
}

std::optional<FaultProblem> CheckFault(const FaultOptions& f, double duration_s,
                                       const std::vector<std::string>& stream_names) {
  if (FaultKeys(f.type).empty())
    return FaultProblem{"type", "unknown fault '" + f.type + "' (outliers, outage, clock_jump, duplicates, freeze)"};
  if (std::find(stream_names.begin(), stream_names.end(), f.stream) == stream_names.end()) {
    std::string names;
    for (const std::string& n : stream_names) names += (names.empty() ? "" : ", ") + n;
    return FaultProblem{"stream", "the scenario writes no stream '" + f.stream + "' (it writes " + names + ")"};
  }
  const std::string span = "[0, " + NumberText(duration_s) + "] s (duration_s)";
  if (f.type == "outliers" || f.type == "duplicates") {
    if (!(f.fraction > 0.0 && f.fraction <= 1.0)) return FaultProblem{"fraction", "must be in (0, 1]"};
    if (f.type == "outliers" && !(f.size > 0.0)) return FaultProblem{"size", "must be > 0"};
  }
  if (f.type == "outage" || f.type == "freeze") {
    if (!(f.start_s >= 0.0 && f.start_s <= duration_s)) return FaultProblem{"start_s", "must be within " + span};
    if (!(f.duration_s > 0.0)) return FaultProblem{"duration_s", "must be > 0"};
  }
  if (f.type == "clock_jump") {
    if (!(f.at_s >= 0.0 && f.at_s <= duration_s)) return FaultProblem{"at_s", "must be within " + span};
    if (!(f.jump_s > 0.0 && f.jump_s <= 3600.0)) {
      return FaultProblem{"jump_s",
                          "must be in (0, 3600] s: a backward jump makes the stamps go backwards, which a recording "
                          "cannot hold"};
    }
  }
  return std::nullopt;
}

std::vector<std::string> ApplyFaults(const std::vector<FaultOptions>& faults, std::uint64_t seed,
                                     recording::Recording* recording) {
  std::vector<std::string> lines;
  for (std::size_t i = 0; i < faults.size(); ++i) {
    const FaultOptions& f = faults[i];
    recording::Stream* s = nullptr;
    for (recording::Stream& candidate : recording->streams)
      if (candidate.info.name == f.stream) s = &candidate;
    if (s == nullptr) continue;  // CheckFault refuses a fault on a stream the scenario does not write
    std::mt19937_64 rng = FaultGenerator(seed, i);
    const std::size_t rows = s->t.size();
    std::string what;
    if (f.type == "outliers") what = "outliers on " + std::to_string(Outliers(f, rng, s));
    if (f.type == "outage") what = "outage removed " + std::to_string(Outage(f, s));
    if (f.type == "clock_jump")
      what = "clock jump of " + NumberText(f.jump_s) + " s on " + std::to_string(ClockJump(f, s));
    if (f.type == "duplicates") what = "duplicates added " + std::to_string(Duplicates(f, rng, s));
    if (f.type == "freeze") what = "freeze repeated a reading on " + std::to_string(Freeze(f, s));
    lines.push_back(f.stream + ": " + what + " of " + std::to_string(rows) + " rows");
  }
  return lines;
}

}  // namespace roamlab::sim
