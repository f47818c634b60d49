#include "frontend/scan_matching_stream.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include <Eigen/Geometry>

#include "common/check.h"

namespace roamlab::frontend {

ScanMatchingStream::ScanMatchingStream(std::string name, double rate_hz, const ScanMatcherOptions& options)
    : name_(std::move(name)), rate_hz_(rate_hz), options_(options) {}

bool ScanMatchingStream::AddScan(Time t, const ScanGeometry& geometry, std::vector<double> ranges) {
  ROAMLAB_CHECK(!t_previous_ || *t_previous_ < t, "scans must be in time order");
  bool matched = false;
  if (t_previous_) {
    const std::int64_t dt_ns = t.nanoseconds() - t_previous_->nanoseconds();
    const double dt = static_cast<double>(dt_ns) * 1e-9;
    const ScanMatch match =
        MatchScansFrom(geometry, previous_scan_, ranges, {Eigen::Vector3d::Zero(), previous_velocity_ * dt}, options_);
    if (match.ok) {
      const double theta = match.pose[2];
      const Eigen::Vector2d v = Eigen::Rotation2Dd(-0.5 * theta) * match.pose.head<2>() / dt;
      previous_velocity_ << match.pose.head<2>() / dt, theta / dt;
      t_.push_back(Time::FromNanoseconds(t.nanoseconds() - dt_ns / 2));
      rows_.push_back({v.x(), v.y(), 0.0, 0.0, 0.0, theta / dt});
      sigma_sum_ += Eigen::Vector2d(std::sqrt(match.covariance(0, 0)), std::sqrt(match.covariance(2, 2))) / dt;
      matched = true;
    } else {
      ++failed_matches_;
    }
  }
  t_previous_ = t;
  previous_scan_ = std::move(ranges);
  return matched;
}

recording::Stream ScanMatchingStream::TakeStream() const {
  recording::Stream stream;
  stream.info.name = name_;
  stream.info.type = recording::StreamType::kScanMatching;
  stream.info.rate_hz = rate_hz_;
  stream.info.columns = recording::FixedColumns(recording::StreamType::kScanMatching);
  stream.info.units = "m/s,rad/s";
  stream.t = t_;
  stream.values.resize(static_cast<Eigen::Index>(rows_.size()), 6);
  for (std::size_t k = 0; k < rows_.size(); ++k)
    for (int c = 0; c < 6; ++c) stream.values(static_cast<Eigen::Index>(k), c) = rows_[k][c];
  const Eigen::Vector2d sigma = sigma_sum_ / std::max<double>(1.0, static_cast<double>(rows_.size()));
  stream.info.noise = {{"sigma_mps", sigma.x()}, {"sigma_radps", sigma.y()}};
  return stream;
}

}  // namespace roamlab::frontend
