#include "frontend/visual_odometry.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <utility>

#include <Eigen/Geometry>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include "common/check.h"

namespace roamlab::frontend {
namespace {

using Matrix6d = Eigen::Matrix<double, 6, 6>;
using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix5d = Eigen::Matrix<double, 5, 5>;
using Vector5d = Eigen::Matrix<double, 5, 1>;

Eigen::Matrix3d Exp(const Eigen::Vector3d& phi) {
  const double angle = phi.norm();
  if (angle < 1e-12) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(angle, phi / angle).toRotationMatrix();
}

Eigen::Vector3d Log(const Eigen::Matrix3d& R) {
  const Eigen::AngleAxisd aa(R);
  return aa.angle() * aa.axis();
}

Eigen::Matrix3d Skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d S;
  S << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return S;
}

// Two unit vectors orthogonal to the unit vector t: the tangent plane of the translation direction.
Eigen::Matrix<double, 3, 2> TangentBasis(const Eigen::Vector3d& t) {
  const Eigen::Vector3d a = std::abs(t.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  const Eigen::Vector3d b1 = t.cross(a).normalized();
  Eigen::Matrix<double, 3, 2> B;
  B.col(0) = b1;
  B.col(1) = t.cross(b1);
  return B;
}

// Relative pose of the pair: X2 = R21 X1 + t21, |t21| = 1, and its 5-parameter perturbation
// R21 = Exp(dtheta) R21_0, t21 = normalize(t21_0 + B dphi).
struct PairPose {
  Eigen::Matrix3d R21;
  Eigen::Vector3d t21;
};

PairPose Perturb(const PairPose& pose, const Eigen::Matrix<double, 3, 2>& B, const Vector5d& d) {
  return {Exp(d.head<3>()) * pose.R21, (pose.t21 + B * d.tail<2>()).normalized()};
}

// Sampson distance of a correspondence (normalized coordinates, homogeneous) to the epipolar geometry E = [t]x R:
// first-order geometric distance in the normalized image plane.
double Sampson(const Eigen::Matrix3d& E, const Eigen::Vector3d& x1, const Eigen::Vector3d& x2) {
  const Eigen::Vector3d Ex1 = E * x1;
  const Eigen::Vector3d Etx2 = E.transpose() * x2;
  const double denominator = Ex1.head<2>().squaredNorm() + Etx2.head<2>().squaredNorm();
  return x2.dot(Ex1) / std::sqrt(std::max(denominator, 1e-30));
}

Eigen::VectorXd SampsonResiduals(const PairPose& pose, const std::vector<Eigen::Vector3d>& x1,
                                 const std::vector<Eigen::Vector3d>& x2) {
  const Eigen::Matrix3d E = Skew(pose.t21) * pose.R21;
  Eigen::VectorXd r(static_cast<Eigen::Index>(x1.size()));
  for (std::size_t i = 0; i < x1.size(); ++i) r[static_cast<Eigen::Index>(i)] = Sampson(E, x1[i], x2[i]);
  return r;
}

// Residuals (2 per point) as a function of 5 parameters, numeric Jacobian by central differences.
Eigen::MatrixXd NumericJacobian5(const std::function<Eigen::VectorXd(const Vector5d&)>& f, Eigen::Index rows) {
  constexpr double kStep = 1e-6;
  Eigen::MatrixXd J(rows, 5);
  for (int k = 0; k < 5; ++k) {
    Vector5d d = Vector5d::Zero();
    d[k] = kStep;
    J.col(k) = (f(d) - f(-d)) / (2.0 * kStep);
  }
  return J;
}

// A floor point: its ray in C1 scaled to the floor, A = R21 X1 is recomputed per pose.
struct FloorPoint {
  Eigen::Vector3d X1;  // on the floor, in C1 [m]
  Eigen::Vector2d x2;  // observed normalized coordinates in C2
};

// Reprojection residual of a floor point for the pose and scale: proj(R21 X1 + s t21) - x2 (normalized units), and
// its derivative with respect to s.
Eigen::Vector2d FloorResidual(const PairPose& pose, double s, const FloorPoint& p, Eigen::Vector2d* d_ds) {
  const Eigen::Vector3d X2 = pose.R21 * p.X1 + s * pose.t21;
  const double inv_z = 1.0 / X2.z();
  if (d_ds != nullptr) {
    const Eigen::Vector3d& t = pose.t21;
    *d_ds =
        Eigen::Vector2d(t.x() * inv_z - X2.x() * t.z() * inv_z * inv_z, t.y() * inv_z - X2.y() * t.z() * inv_z * inv_z);
  }
  return X2.head<2>() * inv_z - p.x2;
}

// Gauss-Newton on the floor reprojection error over the scale alone, from s.
double RefineScale(const PairPose& pose, const std::vector<FloorPoint>& points, const std::vector<int>& use, double s) {
  for (int iteration = 0; iteration < 10; ++iteration) {
    double JtJ = 0.0;
    double Jtr = 0.0;
    for (int i : use) {
      Eigen::Vector2d J;
      const Eigen::Vector2d r = FloorResidual(pose, s, points[static_cast<std::size_t>(i)], &J);
      JtJ += J.squaredNorm();
      Jtr += J.dot(r);
    }
    if (!(JtJ > 0.0)) return s;
    const double step = -Jtr / JtJ;
    s += step;
    if (std::abs(step) < 1e-12 * std::max(1.0, std::abs(s))) break;
  }
  return s;
}

// Camera velocities of step 5 from the pair's pose and scale.
Vector6d Velocities(const PairPose& pose, double s, double dt) {
  const Eigen::Matrix3d R12 = pose.R21.transpose();
  const Eigen::Vector3d p12 = -R12 * pose.t21 * s;
  const Eigen::Vector3d omega = Log(R12) / dt;
  Vector6d out;
  out.head<3>() = Exp(-0.5 * dt * omega) * p12 / dt;
  out.tail<3>() = omega;
  return out;
}

double Median(std::vector<double> values) {
  ROAMLAB_CHECK(!values.empty(), "median of nothing");
  const auto mid = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), mid, values.end());
  return *mid;
}

// Step 2 of the header: pyramidal Lucas-Kanade forward and backward; the tracks that come back to where they
// started, with their flow.
struct Tracks {
  std::vector<cv::Point2f> p1;
  std::vector<cv::Point2f> p2;
  std::vector<double> flow_px;
};

Tracks TrackForwardBackward(const cv::Mat& previous, const cv::Mat& gray, const std::vector<cv::Point2f>& p1,
                            const VisualOdometryOptions& options, double pixel_scale) {
  int window = static_cast<int>(std::lround(options.klt_window_px * pixel_scale)) | 1;
  const cv::Size window_size(window, window);
  const cv::TermCriteria criteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 30, 0.01);
  std::vector<cv::Point2f> p2;
  std::vector<cv::Point2f> p1_back;
  std::vector<unsigned char> status;
  std::vector<unsigned char> status_back;
  std::vector<float> error;
  cv::calcOpticalFlowPyrLK(previous, gray, p1, p2, status, error, window_size, options.klt_pyramid_levels, criteria);
  cv::calcOpticalFlowPyrLK(gray, previous, p2, p1_back, status_back, error, window_size, options.klt_pyramid_levels,
                           criteria);
  const double max_fb = options.max_forward_backward_px * pixel_scale;
  const cv::Rect2f inside(0.0f, 0.0f, static_cast<float>(gray.cols - 1), static_cast<float>(gray.rows - 1));
  Tracks tracks;
  for (std::size_t i = 0; i < p1.size(); ++i) {
    if (!status[i] || !status_back[i] || !inside.contains(p2[i])) continue;
    if (cv::norm(p1_back[i] - p1[i]) > max_fb) continue;
    tracks.p1.push_back(p1[i]);
    tracks.p2.push_back(p2[i]);
    tracks.flow_px.push_back(cv::norm(p2[i] - p1[i]));
  }
  return tracks;
}

// No measurable motion: the covariance of zero velocities, that of a flow at the threshold seen on the optical axis
// (rotation) and at the floor point on the optical axis (translation; the camera height when it does not see the
// floor there).
Matrix6d StationaryCovariance(const VisualOdometryOptions& options, double pixel_scale, double f, double dt) {
  const double sigma_angle = options.stationary_flow_px * pixel_scale / f / dt;
  const double n_z = options.floor_normal_camera.z();
  const double depth = n_z > 0.05 ? options.camera_height_m / n_z : options.camera_height_m;
  Matrix6d covariance = Matrix6d::Zero();
  covariance.topLeftCorner<3, 3>() = Eigen::Matrix3d::Identity() * std::pow(sigma_angle * depth, 2);
  covariance.bottomRightCorner<3, 3>() = Eigen::Matrix3d::Identity() * sigma_angle * sigma_angle;
  return covariance;
}

// Step 3, first half: the essential matrix by 5-point RANSAC and the pose by the cheirality check; the inliers'
// normalized coordinates and their pixels in frame 2. nullopt with fewer than min_inliers.
struct EssentialInliers {
  PairPose pose;
  std::vector<Eigen::Vector3d> x1;
  std::vector<Eigen::Vector3d> x2;
  std::vector<cv::Point2f> p2;
};

std::optional<EssentialInliers> FitEssential(const Tracks& tracks, const PinholeIntrinsics& intrinsics,
                                             const VisualOdometryOptions& options, double pixel_scale) {
  cv::Mat mask;
  const cv::Mat K(intrinsics.K());
  const cv::Mat E = cv::findEssentialMat(tracks.p1, tracks.p2, K, cv::RANSAC, options.ransac_confidence,
                                         options.ransac_threshold_px * pixel_scale, mask);
  cv::Mat R_cv;
  cv::Mat t_cv;
  int inliers = 0;
  if (E.rows == 3 && E.cols == 3) inliers = cv::recoverPose(E, tracks.p1, tracks.p2, K, R_cv, t_cv, mask);
  if (inliers < options.min_inliers) return std::nullopt;
  EssentialInliers out;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) out.pose.R21(r, c) = R_cv.at<double>(r, c);
    out.pose.t21[r] = t_cv.at<double>(r);
  }
  out.pose.t21.normalize();
  const auto normalized = [&intrinsics](const cv::Point2f& p) {
    return Eigen::Vector3d((p.x - intrinsics.cx_px) / intrinsics.fx_px, (p.y - intrinsics.cy_px) / intrinsics.fy_px,
                           1.0);
  };
  for (std::size_t i = 0; i < tracks.p1.size(); ++i) {
    if (!mask.at<unsigned char>(static_cast<int>(i))) continue;
    out.x1.push_back(normalized(tracks.p1[i]));
    out.x2.push_back(normalized(tracks.p2[i]));
    out.p2.push_back(tracks.p2[i]);
  }
  return out;
}

// Step 3, second half: Gauss-Newton on the Sampson error over (R21, t21); the normal matrix at the solution, the
// pixel noise sigma^2 = sum e^2 / (N - 5) and the tangent basis of t21 give the pose covariance sigma^2 (J^T J)^-1.
struct SampsonFit {
  PairPose pose;
  Eigen::Matrix<double, 3, 2> B;
  Matrix5d JtJ;
  double sigma2 = 0.0;
};

SampsonFit RefineOnSampson(PairPose pose, const std::vector<Eigen::Vector3d>& x1,
                           const std::vector<Eigen::Vector3d>& x2) {
  const auto n_inliers = static_cast<Eigen::Index>(x1.size());
  Matrix5d JtJ = Matrix5d::Identity();
  for (int iteration = 0; iteration < 5; ++iteration) {
    const Eigen::Matrix<double, 3, 2> B = TangentBasis(pose.t21);
    const auto residuals = [&](const Vector5d& d) { return SampsonResiduals(Perturb(pose, B, d), x1, x2); };
    const Eigen::VectorXd r = residuals(Vector5d::Zero());
    const Eigen::MatrixXd J = NumericJacobian5(residuals, n_inliers);
    JtJ = J.transpose() * J;
    const Vector5d step = JtJ.ldlt().solve(-J.transpose() * r);
    pose = Perturb(pose, B, step);
    if (step.norm() < 1e-10) break;
  }
  SampsonFit fit;
  fit.pose = pose;
  fit.B = TangentBasis(pose.t21);
  const auto residuals = [&](const Vector5d& d) { return SampsonResiduals(Perturb(pose, fit.B, d), x1, x2); };
  const Eigen::VectorXd r = residuals(Vector5d::Zero());
  const Eigen::MatrixXd J = NumericJacobian5(residuals, n_inliers);
  fit.JtJ = J.transpose() * J;
  fit.sigma2 = r.squaredNorm() / static_cast<double>(n_inliers - 5);
  return fit;
}

// Step 4: the floor points (inliers whose ray meets the floor within 30 camera heights) and the scale they agree on
// by 1-point RANSAC: each floor point's own least-squares scale is a hypothesis; the one with the most points within
// `threshold` (normalized units; ties: smaller squared error) wins, then Gauss-Newton refines it on them. The scale's
// own variance comes from its residuals: sigma_s^2 = sigma^2 / sum |dr/ds|^2 (2 residuals per point). nullopt with
// fewer than min_floor_inliers points or a scale that is not positive.
struct FloorScale {
  std::vector<FloorPoint> floor;
  std::vector<int> inliers;  // into floor
  double s = 0.0;
  double variance = 0.0;
};

std::optional<FloorScale> ScaleFromFloor(const PairPose& pose, const std::vector<Eigen::Vector3d>& x1,
                                         const std::vector<Eigen::Vector3d>& x2, const VisualOdometryOptions& options,
                                         double threshold) {
  const double h = options.camera_height_m;
  const Eigen::Vector3d& n = options.floor_normal_camera;
  FloorScale out;
  std::vector<FloorPoint>& floor = out.floor;
  for (std::size_t i = 0; i < x1.size(); ++i) {
    const double n_dot = n.dot(x1[i]);
    if (n_dot * 30.0 < x1[i].norm()) continue;
    floor.push_back({x1[i] * (h / n_dot), x2[i].head<2>()});
  }
  const auto inliers_of = [&](double s, double* cost) {
    std::vector<int> use;
    *cost = 0.0;
    for (std::size_t i = 0; i < floor.size(); ++i) {
      const double e = FloorResidual(pose, s, floor[i], nullptr).norm();
      if (e < threshold) {
        use.push_back(static_cast<int>(i));
        *cost += e * e;
      }
    }
    return use;
  };
  std::vector<int>& best = out.inliers;
  double best_s = 0.0;
  double best_cost = 0.0;
  for (std::size_t i = 0; i < floor.size(); ++i) {
    const double s = RefineScale(pose, floor, {static_cast<int>(i)}, h);
    if (!(s > 0.0) || !std::isfinite(s)) continue;
    double cost = 0.0;
    std::vector<int> use = inliers_of(s, &cost);
    if (use.size() > best.size() || (use.size() == best.size() && cost < best_cost)) {
      best = std::move(use);
      best_s = s;
      best_cost = cost;
    }
  }
  double s = best_s;
  if (static_cast<int>(best.size()) >= options.min_floor_inliers) {
    s = RefineScale(pose, floor, best, s);
    best = inliers_of(s, &best_cost);
    if (static_cast<int>(best.size()) >= 2) s = RefineScale(pose, floor, best, s);
  }
  if (static_cast<int>(best.size()) < options.min_floor_inliers || !(s > 0.0)) return std::nullopt;
  out.s = s;
  double floor_r2 = 0.0;
  double floor_J2 = 0.0;
  for (int i : best) {
    Eigen::Vector2d J;
    floor_r2 += FloorResidual(pose, s, floor[static_cast<std::size_t>(i)], &J).squaredNorm();
    floor_J2 += J.squaredNorm();
  }
  out.variance = floor_r2 / std::max(1.0, 2.0 * best.size() - 1.0) / floor_J2;
  return out;
}

// Step 6: the first-order covariance of the velocities over the parameters (dtheta, dphi, ds), the scale re-solved
// for each perturbed pose.
Matrix6d OutputCovariance(const SampsonFit& fit, const FloorScale& scale, double dt) {
  const auto outputs = [&](const Vector6d& d) {
    const PairPose perturbed = Perturb(fit.pose, fit.B, d.head<5>());
    const double s_perturbed = RefineScale(perturbed, scale.floor, scale.inliers, scale.s) + d[5];
    return Velocities(perturbed, s_perturbed, dt);
  };
  Matrix6d J_out;
  for (int k = 0; k < 6; ++k) {
    const double step = k < 5 ? 1e-6 : 1e-6 * scale.s;
    Vector6d d = Vector6d::Zero();
    d[k] = step;
    J_out.col(k) = (outputs(d) - outputs(-d)) / (2.0 * step);
  }
  Matrix6d input_covariance = Matrix6d::Zero();
  input_covariance.topLeftCorner<5, 5>() = fit.sigma2 * fit.JtJ.inverse();
  input_covariance(5, 5) = scale.variance;
  // Assigned, not constructed from the product: Eigen evaluates the two differently (a temporary for `=`), and the
  // recorded streams keep the rounding of the assignment.
  Matrix6d covariance = Matrix6d::Zero();
  covariance = J_out * input_covariance * J_out.transpose();
  return covariance;
}

}  // namespace

std::string VisualOdometryOptions::Validate() const {
  if (!(camera_height_m > 0.0) || !std::isfinite(camera_height_m)) return "camera_height_m must be positive";
  if (!floor_normal_camera.allFinite() || std::abs(floor_normal_camera.norm() - 1.0) > 1e-6) {
    return "floor_normal_camera must be a unit vector";
  }
  if (max_features < 8 || grid_columns < 1 || grid_rows < 1) return "max_features >= 8 and a grid of at least 1x1";
  if (!(feature_quality > 0.0 && feature_quality < 1.0)) return "feature_quality must be in (0, 1)";
  if (!(min_feature_distance_px > 0.0) || klt_window_px < 5 || klt_pyramid_levels < 0) {
    return "min_feature_distance_px > 0, klt_window_px >= 5, klt_pyramid_levels >= 0";
  }
  if (!(max_forward_backward_px > 0.0) || !(ransac_threshold_px > 0.0) || !(floor_threshold_px > 0.0)) {
    return "pixel thresholds must be positive";
  }
  if (!(ransac_confidence > 0.0 && ransac_confidence < 1.0)) return "ransac_confidence must be in (0, 1)";
  if (!(stationary_flow_px >= 0.0)) return "stationary_flow_px must not be negative";
  if (min_tracks < 8 || min_inliers < 6 || min_floor_inliers < 2) {
    return "min_tracks >= 8, min_inliers >= 6, min_floor_inliers >= 2";
  }
  return "";
}

const char* VoFailureName(VoFailure failure) {
  switch (failure) {
    case VoFailure::kNone:
      return "none";
    case VoFailure::kTooFewFeatures:
      return "too_few_features";
    case VoFailure::kTooFewTracks:
      return "too_few_tracks";
    case VoFailure::kTooFewInliers:
      return "too_few_inliers";
    case VoFailure::kNoScale:
      return "no_scale";
  }
  return "unknown";
}

VisualOdometry::VisualOdometry(const PinholeIntrinsics& intrinsics, const VisualOdometryOptions& options)
    : intrinsics_(intrinsics), options_(options), pixel_scale_(intrinsics.width_px / 320.0) {
  const std::string problem = options.Validate();
  ROAMLAB_CHECK(problem.empty(), "VisualOdometryOptions: " << problem);
  ROAMLAB_CHECK(intrinsics.width_px > 0 && intrinsics.height_px > 0 && intrinsics.fx_px > 0.0 && intrinsics.fy_px > 0.0,
                "intrinsics");
}

void VisualOdometry::Fail(VoFailure failure) {
  last_failure_ = failure;
  ++counters_.failures;
  switch (failure) {
    case VoFailure::kTooFewFeatures:
      ++counters_.too_few_features;
      break;
    case VoFailure::kTooFewTracks:
      ++counters_.too_few_tracks;
      break;
    case VoFailure::kTooFewInliers:
      ++counters_.too_few_inliers;
      break;
    case VoFailure::kNoScale:
      ++counters_.no_scale;
      break;
    case VoFailure::kNone:
      break;
  }
}

std::optional<VoEstimate> VisualOdometry::ProcessFrame(Time t, const cv::Mat& gray) {
  ROAMLAB_CHECK(gray.type() == CV_8UC1 && gray.cols == intrinsics_.width_px && gray.rows == intrinsics_.height_px,
                "VisualOdometry wants CV_8UC1 " << intrinsics_.width_px << "x" << intrinsics_.height_px);
  ROAMLAB_CHECK(!t_previous_ || *t_previous_ < t, "frames must be in time order");
  ++counters_.frames;
  last_failure_ = VoFailure::kNone;
  std::optional<VoEstimate> estimate;
  if (t_previous_) {
    ++counters_.pairs;
    estimate = Estimate(t, gray);
    if (estimate) ++counters_.estimates;
  } else {
    previous_points_.clear();
  }
  // This frame becomes frame 1 of the next pair; its surviving tracks are topped up with new corners.
  gray.copyTo(previous_);
  t_previous_ = t;
  DetectFeatures(previous_, &previous_points_);
  return estimate;
}

void VisualOdometry::DetectFeatures(const cv::Mat& gray, std::vector<cv::Point2f>* points) const {
  const double min_distance = options_.min_feature_distance_px * pixel_scale_;
  // Keep away from the corners already tracked.
  cv::Mat mask(gray.size(), CV_8UC1, cv::Scalar(255));
  for (const cv::Point2f& p : *points) cv::circle(mask, p, static_cast<int>(std::ceil(min_distance)), 0, -1);
  // Per grid cell, top up to its share of max_features.
  const int cells = options_.grid_columns * options_.grid_rows;
  const int per_cell = std::max(1, options_.max_features / cells);
  std::vector<int> count(static_cast<std::size_t>(cells), 0);
  const auto cell_of = [&](const cv::Point2f& p) {
    const int c = std::clamp(static_cast<int>(p.x * options_.grid_columns / gray.cols), 0, options_.grid_columns - 1);
    const int r = std::clamp(static_cast<int>(p.y * options_.grid_rows / gray.rows), 0, options_.grid_rows - 1);
    return r * options_.grid_columns + c;
  };
  for (const cv::Point2f& p : *points) ++count[static_cast<std::size_t>(cell_of(p))];
  std::vector<cv::Point2f> corners;
  for (int r = 0; r < options_.grid_rows; ++r) {
    for (int c = 0; c < options_.grid_columns; ++c) {
      const int wanted = per_cell - count[static_cast<std::size_t>(r * options_.grid_columns + c)];
      if (wanted <= 0) continue;
      const cv::Rect cell(c * gray.cols / options_.grid_columns, r * gray.rows / options_.grid_rows,
                          (c + 1) * gray.cols / options_.grid_columns - c * gray.cols / options_.grid_columns,
                          (r + 1) * gray.rows / options_.grid_rows - r * gray.rows / options_.grid_rows);
      cv::goodFeaturesToTrack(gray(cell), corners, wanted, options_.feature_quality, min_distance, mask(cell));
      for (const cv::Point2f& p : corners) points->emplace_back(p.x + cell.x, p.y + cell.y);
    }
  }
}

std::optional<VoEstimate> VisualOdometry::Estimate(Time t, const cv::Mat& gray) {
  const double f = intrinsics_.fx_px;
  const double dt = SecondsBetween(*t_previous_, t);
  std::vector<cv::Point2f> p1 = std::move(previous_points_);
  previous_points_.clear();
  if (static_cast<int>(p1.size()) < options_.min_tracks) {
    Fail(VoFailure::kTooFewFeatures);
    return std::nullopt;
  }

  // Step 2: tracks that survive the forward-backward check.
  const Tracks tracks = TrackForwardBackward(previous_, gray, p1, options_, pixel_scale_);
  const int n_tracks = static_cast<int>(tracks.p1.size());
  if (n_tracks < options_.min_tracks) {
    previous_points_ = tracks.p2;
    Fail(VoFailure::kTooFewTracks);
    return std::nullopt;
  }
  VoEstimate out;
  out.t_begin = *t_previous_;
  out.t_end = t;
  out.t_mid = Time::FromNanoseconds(t_previous_->nanoseconds() + (t.nanoseconds() - t_previous_->nanoseconds()) / 2);
  out.tracks = n_tracks;
  if (Median(tracks.flow_px) < options_.stationary_flow_px * pixel_scale_) {
    previous_points_ = tracks.p2;
    out.covariance = StationaryCovariance(options_, pixel_scale_, f, dt);
    out.stationary = true;
    return out;
  }

  // Step 3: rotation and translation direction; the inliers are the tracks carried to the next pair.
  std::optional<EssentialInliers> essential = FitEssential(tracks, intrinsics_, options_, pixel_scale_);
  if (!essential) {
    previous_points_ = tracks.p2;
    Fail(VoFailure::kTooFewInliers);
    return std::nullopt;
  }
  previous_points_ = std::move(essential->p2);
  out.inliers = static_cast<int>(essential->x1.size());
  const SampsonFit fit = RefineOnSampson(essential->pose, essential->x1, essential->x2);
  out.pixel_sigma_px = std::sqrt(fit.sigma2) * f;

  // Step 4: the metric scale from the floor points.
  const std::optional<FloorScale> scale =
      ScaleFromFloor(fit.pose, essential->x1, essential->x2, options_, options_.floor_threshold_px * pixel_scale_ / f);
  if (!scale) {
    Fail(VoFailure::kNoScale);
    return std::nullopt;
  }
  out.floor_inliers = static_cast<int>(scale->inliers.size());

  // Steps 5 and 6: velocities and their covariance.
  out.covariance = OutputCovariance(fit, *scale, dt);
  const Vector6d velocities = Velocities(fit.pose, scale->s, dt);
  out.v_camera_mps = velocities.head<3>();
  out.omega_camera_radps = velocities.tail<3>();
  out.R_prev_curr = fit.pose.R21.transpose();
  out.p_prev_curr_m = -out.R_prev_curr * fit.pose.t21 * scale->s;
  return out;
}

}  // namespace roamlab::frontend
