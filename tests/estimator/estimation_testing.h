// Shared pieces of the end-to-end estimator tests: an estimator configuration for the synthetic ATV recording
// (tests/support/synthetic.h) with selectable free parameters.
#pragma once

#include <string>
#include <vector>

#include "estimator/config.h"

namespace roamlab::estimator::testing {

// The ATV configuration: Ackermann master, IMU (gyroscope, accelerometer, magnetometer) and GPS, with the seed's
// Section V noise. `free` lists the parameters to estimate; their initial values are the nominal ones (lever arm 0,
// identity misalignment and A, zero bias, kv_over_L 0.8, k_theta 1, k_gamma 0); all others are fixed at the truth.
std::string AtvConfigYaml(const std::vector<std::string>& free, int window = 40);

EstimatorConfig AtvConfig(const std::vector<std::string>& free, int window = 40);

}  // namespace roamlab::estimator::testing
