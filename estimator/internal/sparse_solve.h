// A sparse symmetric positive definite solve with CHOLMOD, shared by the marginal covariance (covariance.h) and the
// information analysis (information.h).
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "common/status.h"

namespace roamlab::estimator::internal {

// H^-1 rhs with H's lower triangle factored by CHOLMOD supernodal Cholesky, regularized very slightly (1e-10 of each
// diagonal entry, at least 1e-10) when a gauge freedom leaves H singular; an error when it is singular even so.
Result<Eigen::MatrixXd> SolveSparseSpd(Eigen::SparseMatrix<double> H, const Eigen::MatrixXd& rhs);

}  // namespace roamlab::estimator::internal
