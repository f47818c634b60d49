#include "estimator/tracking_io.h"

#include <cstdio>
#include <string>

#include <nlohmann/json.hpp>

#include "common/atomic_file.h"
#include "common/time.h"
#include "estimator/internal/json_io.h"
#include "recording/trajectory.h"

namespace roamlab::estimator {
namespace {

Status WriteCovariance(const TrackingResult& r, const std::string& path) {
  std::string cov = "t,xx,xy,xz,yx,yy,yz,zx,zy,zz\n";
  char buf[64];
  for (std::size_t i = 0; i < r.trajectory.size(); ++i) {
    cov += FormatSeconds(r.trajectory[i].t);
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) {
        std::snprintf(buf, sizeof buf, ",%.17g", r.position_covariance[i](a, b));
        cov += buf;
      }
    cov += "\n";
  }
  return WriteFileAtomic(path, cov);
}

}  // namespace

int RejectedMeasurements(const TrackingResult& result) {
  int rejected = 0;
  for (const auto& [name, c] : result.counts) rejected += c.rejected;
  return rejected;
}

double RealtimeFactor(const TrackingResult& result) {
  const Trajectory& t = result.trajectory;
  const double duration = t.size() > 1 ? SecondsBetween(t.front().t, t.back().t) : 0.0;
  return result.total_seconds > 0 ? duration / result.total_seconds : 0.0;
}

Status WriteTrackingFiles(const TrackingResult& r, int window, const std::string& dir) {
  Status st = WriteTum(r.trajectory, dir + "/trajectory.tum");
  if (!st.ok()) return st;
  st = WriteCovariance(r, dir + "/covariance.csv");
  if (!st.ok()) return st;
  const nlohmann::json summary = {{"poses", r.trajectory.size()},
                                  {"updates", r.updates},
                                  {"mean_update_s", r.mean_update_s},
                                  {"max_update_s", r.max_update_s},
                                  {"p99_update_s", r.p99_update_s},
                                  {"mean_iterations", r.mean_iterations},
                                  {"factor_evaluations", r.factor_evaluations},
                                  {"factor_carries", r.factor_carries},
                                  {"seconds", r.total_seconds},
                                  {"realtime_factor", RealtimeFactor(r)},
                                  {"window", window},
                                  {"rejected_measurements", RejectedMeasurements(r)},
                                  {"measurements", internal::CountsJson(r.counts)}};
  return internal::WriteJson(summary, dir + "/summary.json");
}

}  // namespace roamlab::estimator
