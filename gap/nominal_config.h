// The nominal estimator configuration of a simulated robot: what the diagnosis (gap/diagnose.h) takes as the model a
// recording of that robot is compared with, built from the scenario's sensors and the robot's MuJoCo model.
#pragma once

#include <string>

#include "common/status.h"
#include "estimator/config.h"
#include "sim/scenario.h"

namespace roamlab::gap {

// The nominal estimator configuration of a scenario, no outlier gating (the chi-square comparisons need the same
// measurements in every fit) and no robust loss (they need Gaussian costs):
//   - ackermann: the streams its sensors produce with the scenario's noise, the Table I calibration free with the
//     scenario's values as the initial guess (staged as configs/atv_calibration.yaml), k_gamma fixed at the scenario's
//     value (the handlebar sensor's zero is believed; a steering_offset is a departure from it), gyroscope scale 1 and
//     cornering compliance 0 fixed (eq. 15 as written), the magnetometer's motor interference 0 fixed on the IMU's
//     specific force as the drive torque's proxy (c = m r / 2 from the nominal vehicle's mass and rear tire radius,
//     models/magnetometer.h);
//   - differential_drive, omni3 and mecanum: the wheel encoders (master) with the platform geometry measured on the
//     robot's model, one radius free for all wheels, the yaw lever arm (baseline, distance, lx_plus_ly) fixed, and
//     the gyroscope with the IMU misalignment free.
// Errors: another robot kind, a master or yaw sensor missing, or a wheeled scenario that renames its encoder stream or
// its columns or states per-wheel geometry keys (the real robots' scenarios; the real recordings have their own
// configurations in configs/real/).
Result<estimator::EstimatorConfig> NominalConfig(const sim::Scenario& scenario);

}  // namespace roamlab::gap
