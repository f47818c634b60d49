// One seeded stream of zero-mean Gaussian noise per noise source (no global generator). The generator is a
// std::mt19937_64 seeded with std::seed_seq{low 32 bits of seed, high 32 bits of seed, source}, so every source has
// its own sequence, the same seed and source always give the same numbers, and adding a source never shifts another.
#pragma once

#include <cstdint>
#include <random>

#include <Eigen/Core>

namespace roamlab::sim {

// Source indices; new sources get new numbers at the end, existing numbers never change.
enum class NoiseSource : std::uint32_t {
  kGyro = 0,
  kAccel = 1,
  kMagnetometer = 2,
  kGps = 3,
  kSpeed = 4,
  kSteering = 5,
  kLaserRange = 6,
  kGyroBiasWalk = 7,  // the gyro_bias_drift effect's random walk
  kGpsMultipath = 8,  // the gps_multipath effect's Gauss-Markov error
  kMocapPosition = 9,
  kMocapOrientation = 10,
};

class NoiseStream {
 public:
  // A disabled stream returns zeros and draws nothing.
  NoiseStream(std::uint64_t seed, NoiseSource source, bool enabled = true) : enabled_(enabled) {
    std::seed_seq sequence{static_cast<std::uint32_t>(seed), static_cast<std::uint32_t>(seed >> 32),
                           static_cast<std::uint32_t>(source)};
    generator_.seed(sequence);
  }

  double Draw(double sigma) { return enabled_ ? sigma * normal_(generator_) : 0.0; }
  // Three independent draws in x, y, z order.
  Eigen::Vector3d Draw3(double sigma) {
    const double x = Draw(sigma);
    const double y = Draw(sigma);
    const double z = Draw(sigma);
    return Eigen::Vector3d(x, y, z);
  }

 private:
  bool enabled_;
  std::mt19937_64 generator_;
  std::normal_distribution<double> normal_{0.0, 1.0};
};

}  // namespace roamlab::sim
