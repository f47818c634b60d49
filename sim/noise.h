// One seeded stream of zero-mean Gaussian noise per noise source (no global generator). The generator is a
// std::mt19937_64 seeded with std::seed_seq{low 32 bits of seed, high 32 bits of seed, source}, so every source has
// its own sequence, the same seed and source always give the same numbers, and adding a source never shifts another.
// A sensor's noise may be coloured (GaussMarkovNoise): a first-order Gauss-Markov process with the same stationary
// sigma, drawn from the same stream (one normal number per sample and axis, as white noise draws).
#pragma once

#include <cmath>
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

// First-order Gauss-Markov noise per axis, sampled every period_s: e(0) = sigma n(0) and
//   e(k+1) = a e(k) + sigma sqrt(1 - a^2) n(k+1),  a = exp(-period_s / correlation_s),
// a stationary process with std sigma and autocorrelation exp(-|lag| / correlation_s). correlation_s = 0 (the
// default) is white noise: exactly the numbers NoiseStream::Draw gives. Draw and Draw3 keep their own states (a stream
// uses one of them).
class GaussMarkovNoise {
 public:
  GaussMarkovNoise(std::uint64_t seed, NoiseSource source, bool enabled = true) : stream_(seed, source, enabled) {}

  // correlation_s >= 0 [s], period_s > 0 [s]: the sample period of the stream drawing from it.
  void SetCorrelation(double correlation_s, double period_s) {
    a_ = correlation_s > 0.0 && period_s > 0.0 ? std::exp(-period_s / correlation_s) : 0.0;
  }

  double Draw(double sigma) {
    if (a_ == 0.0 || !started_scalar_) {
      started_scalar_ = true;
      return scalar_ = stream_.Draw(sigma);
    }
    return scalar_ = a_ * scalar_ + stream_.Draw(sigma * std::sqrt(1.0 - a_ * a_));
  }
  Eigen::Vector3d Draw3(double sigma) {
    if (a_ == 0.0 || !started_vector_) {
      started_vector_ = true;
      return vector_ = stream_.Draw3(sigma);
    }
    return vector_ = a_ * vector_ + stream_.Draw3(sigma * std::sqrt(1.0 - a_ * a_));
  }

 private:
  NoiseStream stream_;
  double a_ = 0.0;
  bool started_scalar_ = false;
  bool started_vector_ = false;
  double scalar_ = 0.0;
  Eigen::Vector3d vector_ = Eigen::Vector3d::Zero();
};

}  // namespace roamlab::sim
