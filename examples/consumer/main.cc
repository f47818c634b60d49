// roamlab as a library: a user's own error model (range_beacon.h) registered by name, used from an estimator
// configuration like a built-in model, on a recording written and read back with roamlab's recording library, then
// solved by the offline calibration. Prints the antenna's lever arm against the truth and the trajectory's error, and
// exits 1 when an estimate is off by more than four of its standard deviations or a range sample was not attached.
//
//   consumer_example [WORK_DIR]     (default: a fresh directory under the system's temporary directory)
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

#include "beacon_drive.h"
#include "estimator/calibration.h"
#include "estimator/config.h"
#include "range_beacon.h"
#include "recording/recording.h"

namespace {

int Fail(const std::string& message) {
  std::fprintf(stderr, "consumer_example: %s\n", message.c_str());
  return 1;
}

}  // namespace

int main(int argc, char** argv) {
  namespace fs = std::filesystem;
  using namespace roamlab;
  const roamlab::Status registered = beacon::RegisterRangeBeaconModel();
  if (!registered.ok()) return Fail(registered.message());

  const beacon::BeaconDriveOptions drive;
  const fs::path work = argc > 1 ? fs::path(argv[1]) : fs::temp_directory_path() / "roamlab_consumer_example";
  const std::string directory = (work / "beacon_drive").string();
  fs::remove_all(directory);
  const roamlab::Status written = recording::WriteRecording(beacon::SimulateBeaconDrive(drive), directory);
  if (!written.ok()) return Fail(written.message());
  const Result<recording::Recording> rec = recording::ReadRecording(directory);
  if (!rec.ok()) return Fail(rec.status().message());

  const Result<estimator::EstimatorConfig> config =
      estimator::ParseEstimatorConfig(beacon::BeaconDriveConfig(drive), "beacon_drive.yaml");
  if (!config.ok()) return Fail(config.status().message());
  const Result<estimator::CalibrationResult> result = estimator::Calibrate(config.value(), rec.value());
  if (!result.ok()) return Fail(result.status().message());
  const estimator::CalibrationResult& r = result.value();

  int failures = 0;
  for (const auto& [stream, counts] : r.counts) {
    std::printf("%-9s attached %d, outside %d, rejected %d\n", stream.c_str(), counts.attached, counts.outside,
                counts.rejected);
    if (stream != "odometer" && counts.attached != static_cast<int>(rec.value().Find(stream)->t.size())) ++failures;
  }
  for (const estimator::ParameterEstimate& p : r.parameters) {
    if (p.name != "antenna.lever_arm") continue;
    for (int i = 0; i < 2; ++i) {
      const double error = p.estimate[i] - drive.p_body_antenna[i];
      std::printf("lever_arm[%d] = %.4f m (truth %.4f, std %.4f, error %.1f std)\n", i, p.estimate[i],
                  drive.p_body_antenna[i], p.std[i], error / p.std[i]);
      if (!(std::abs(error) <= 4.0 * p.std[i])) ++failures;
    }
  }
  double sum_sq = 0.0;
  const Trajectory& truth = *rec.value().ground_truth;
  for (std::size_t k = 0; k < r.trajectory.size() && k < truth.size(); ++k)
    sum_sq += (r.trajectory[k].p_world_body - truth[k].p_world_body).squaredNorm();
  const double rmse_m = std::sqrt(sum_sq / static_cast<double>(r.trajectory.size()));
  std::printf("trajectory: %zu poses, position RMSE %.3f m\n", r.trajectory.size(), rmse_m);
  if (r.trajectory.size() != truth.size()) ++failures;
  if (failures > 0) return Fail(std::to_string(failures) + " check(s) failed");
  std::printf("consumer_example: ok\n");
  return 0;
}
