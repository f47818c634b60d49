// Calibration parameters against their true values (truth.yaml): one row per parameter with truth, estimate, standard
// deviation, error and error / std per component (the seed's Table I, with the uncertainty the seed leaves out).
//
// Kinds follow the manifold named in calibration.json:
//   kVector ("R<n>")  n values. error = estimate - truth, std per component.
//   kQuaternion ("S3") [w, x, y, z], Hamilton. std has 3 components: the body-frame rotation vector d of the right
//                      perturbation q = q_hat Exp(d) [rad] (estimator/geometry.h). So that error and std compare, the
//                      error is that same tangent vector between truth and estimate:
//                          error = Log(q_true^-1 q_est)  [rad, 3 components]
//                      angle_error_deg = |error| in degrees (the rotation angle between truth and estimate), and
//                      component_error = q_est - q_true per component [w, x, y, z] after choosing the sign of q_est
//                      that makes w_true w_est + v_true . v_est >= 0 (q and -q are the same rotation).
//   kPose ("SE3")     [x, y, z, qw, qx, qy, qz], std has 6 components [dp (m), dtheta (rad)]:
//                          error = [p_est - p_true, Log(q_true^-1 q_est)]
//                      angle_error_deg and component_error (7 values, quaternion sign chosen as above) as for S3.
// error_over_std is error / std per component (NaN where the std is unknown, zero or not finite); |error_over_std| much
// above 3 says the reported uncertainty is too small for the actual error.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "common/status.h"

namespace roamlab::eval {

enum class ParameterKind { kVector, kQuaternion, kPose };

// "R<n>" (n >= 1) -> kVector, "S3" -> kQuaternion, "SE3" -> kPose; nullopt otherwise.
std::optional<ParameterKind> ParameterKindFromManifold(const std::string& manifold);

struct ParameterEstimate {
  ParameterKind kind = ParameterKind::kVector;
  std::vector<double> estimate;    // ambient values (4 for S3, 7 for SE3)
  std::vector<double> std;         // tangent standard deviations (3 for S3, 6 for SE3); NaN = unknown; may be empty
  std::string observability = "";  // the estimator's verdict ("observable", "weak", "unobservable"); "" = unknown
};

struct ParameterComparison {
  std::string name;
  ParameterKind kind = ParameterKind::kVector;
  std::vector<double> truth;
  std::vector<double> estimate;
  std::vector<double> std;              // tangent size; NaN where unknown
  std::vector<double> error;            // tangent size (see the table above)
  std::vector<double> error_over_std;   // tangent size
  double angle_error_deg = 0.0;         // rotations only (NaN for kVector)
  std::vector<double> component_error;  // rotations only: ambient size (empty for kVector)
  std::string observability;            // as in the estimate; "" = unknown
};

// Compares one parameter. Errors (bad data, naming the parameter): sizes that do not fit the kind (vector: truth,
// estimate and a non-empty std of one size; S3: 4, 4, 3; SE3: 7, 7, 6), a non-finite truth or estimate, a zero
// quaternion.
Result<ParameterComparison> CompareParameter(const std::string& name, const std::vector<double>& truth,
                                             const ParameterEstimate& estimate);

// The rows for every estimated parameter that has a true value, by name; the other estimated names go to
// `without_truth` when given.
Result<std::vector<ParameterComparison>> CompareParameters(const std::map<std::string, std::vector<double>>& truth,
                                                           const std::map<std::string, ParameterEstimate>& estimates,
                                                           std::vector<std::string>* without_truth = nullptr);

// Reads parameters.NAME.{estimate, std, manifold, observability} from a calibration.json written by `roamlab calibrate`
// (std entries may be null: unknown; a missing manifold means "R<n>"). Errors name the file and the parameter.
Result<std::map<std::string, ParameterEstimate>> ReadCalibrationEstimates(const std::string& path);

// {NAME: {"truth": [...], "estimate": [...], "std": [...], "error": [...], "error_over_std": [...], "manifold": "..",
//         "observability": ".." when known, rotations also "angle_error_deg": x, "component_error": [...]}}; NaN as
//         null.
nlohmann::json ParameterTableJson(const std::vector<ParameterComparison>& rows);

}  // namespace roamlab::eval
