// Least-squares ellipsoid fit of raw three-axis magnetometer samples: the hard-iron centre and the soft-iron shape.
//
// The raw field z of a magnetometer turned through many orientations lies on an ellipsoid
//   (z - b)^T M (z - b) = 1,        M symmetric positive definite,
// the image of the sphere of the Earth's field magnitude under the soft-iron distortion, moved by the hard-iron
// offset b. FitEllipsoid fits the general quadric
//   a x^2 + b y^2 + c z^2 + 2 f yz + 2 g xz + 2 h xy + 2 p x + 2 q y + 2 r z + d = 0
// algebraically (the right singular vector of the smallest singular value of the N x 10 design matrix, on samples
// centred at their mean and scaled by their rms distance from it, for conditioning), then converts it:
//   Q = [a h g; h b f; g f c],  u = [p q r]:   centre = -Q^-1 u,   M = Q / (centre^T Q centre - d).
// When that quadric is no ellipsoid (M not positive definite: the samples cover too little of it, e.g. a device that is
// only turned about one axis, whose noise then bends the fit into a hyperboloid), the fit is repeated with Li and
// Griffiths' ellipsoid-specific normalization 4 J - I^2 = 1 instead of |v| = 1 (I = a + b + c, J = ab + bc + ca -
// f^2 - g^2 - h^2; it admits only ellipsoids whose shortest axis is at least half the longest) and `constrained` is
// set. It fails when neither gives an ellipsoid.
//
// Normalization (what `correction` and `radius` mean): radius r is the geometric mean of the ellipsoid's semi-axes,
// det(M)^(-1/6), and correction W = r M^(1/2) (the symmetric square root), so that |W (z - b)| = r for every z on the
// ellipsoid and det(W) = 1: W maps the raw field onto the sphere of radius r without changing the volume, i.e. r is
// the field magnitude the fit's scale stands for. The distortion is W^-1: z = W^-1 h + b with |h| = r.
//
// A magnetometer model z = A h^(S) + b (seed 000, eq. 10) with the Earth's field of magnitude r has A A^T = W^-2 for
// any A that maps the same sphere onto the same ellipsoid (A = W^-1 R with R orthogonal: a rotation that the sensor's
// misalignment can equally hold), so SymmetricFactor(A) = (A A^T)^(1/2) is the quantity to compare with W^-1.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "common/status.h"

namespace roamlab::eval {

struct EllipsoidFit {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();          // hard-iron offset b [units of z]
  Eigen::Matrix3d correction = Eigen::Matrix3d::Identity();  // W: symmetric, det 1
  double radius = 0.0;                                       // r [units of z]
  double rms_residual = 0.0;                                 // rms of |W (z - b)| - r over the samples [units of z]
  bool constrained = false;                                  // the ellipsoid-specific fit was needed (header comment)
};

// kGeneral: the general quadric, the ellipsoid-specific fit when that is no ellipsoid (header comment);
// kEllipsoidSpecific: the ellipsoid-specific fit only.
enum class EllipsoidFitMethod { kGeneral, kEllipsoidSpecific };

// At least 10 samples, finite. Errors: too few samples, degenerate spread, not an ellipsoid.
Result<EllipsoidFit> FitEllipsoid(const std::vector<Eigen::Vector3d>& samples,
                                  EllipsoidFitMethod method = EllipsoidFitMethod::kGeneral);

// The Cramer-Rao covariance of an ellipsoid's centre [units of z ^2] on the given samples, whatever method fits it: the
// inverse of the information that samples scattered about `fit`'s ellipsoid (x - b)^T M (x - b) = 1 with white noise
// of std `sigma` along its normal hold about its nine parameters (b and M's six entries), the centre's block. Each
// sample's first-order distance from the ellipsoid, d = (sqrt(q) - 1) sqrt(q) / |M y| with y = z - b and
// q = y^T M y, has the Jacobian -M y / |M y| (the unit normal) in b and y_j y_k / |M y| (diagonal: y_j^2 / (2 |M y|))
// in M's entries, at q = 1. What limits it is the samples' coverage: on a full sphere of N samples each component's
// std is sqrt(3 / N) sigma; on a cap, the centre trades off against the shape along the cap's axis. Infinite where the
// samples leave a direction of the nine undetermined.
Eigen::Matrix3d EllipsoidCentreCovariance(const EllipsoidFit& fit, const std::vector<Eigen::Vector3d>& samples,
                                          double sigma);

// (A A^T)^(1/2): the symmetric positive semi-definite factor of A's polar decomposition A = P R.
Eigen::Matrix3d SymmetricFactor(const Eigen::Matrix3d& A);

}  // namespace roamlab::eval
