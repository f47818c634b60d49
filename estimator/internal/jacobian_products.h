// Accumulation of whitened Jacobian blocks into normal equations: dst += J_a^T J_b and g += J_a^T r, with fixed-size
// kernels for the block sizes of the error models (3, 4 or 6 rows; 1, 3, 6 or 9 columns) and coefficient-wise
// products otherwise (at these sizes cheaper than a blocked product). Shared by the sparse normal equations and the
// dense ones of the marginalization.
#pragma once

#include <cstddef>

#include <Eigen/Core>

namespace roamlab::estimator::internal {

namespace jacobian_products_detail {

// dst (A x B block of a column-major array, column stride `stride`) += Ja^T Jb, Ja M x A, Jb M x B.
template <int M, int A, int B>
void AddProductFixed(const double* ja, const double* jb, double* dst, std::ptrdiff_t stride) {
  Eigen::Map<Eigen::Matrix<double, A, B>, 0, Eigen::OuterStride<>> block(dst, A, B, Eigen::OuterStride<>(stride));
  block.noalias() += Eigen::Map<const Eigen::Matrix<double, M, A>>(ja).transpose() *
                     Eigen::Map<const Eigen::Matrix<double, M, B>>(jb);
}

template <int M, int A>
bool AddProductColumns(const double* ja, const double* jb, int b, double* dst, std::ptrdiff_t stride) {
  switch (b) {
    case 1: AddProductFixed<M, A, 1>(ja, jb, dst, stride); return true;
    case 3: AddProductFixed<M, A, 3>(ja, jb, dst, stride); return true;
    case 6: AddProductFixed<M, A, 6>(ja, jb, dst, stride); return true;
    case 9: AddProductFixed<M, A, 9>(ja, jb, dst, stride); return true;
    default: return false;
  }
}
template <int M>
bool AddProductRows(const double* ja, int a, const double* jb, int b, double* dst, std::ptrdiff_t stride) {
  switch (a) {
    case 1: return AddProductColumns<M, 1>(ja, jb, b, dst, stride);
    case 3: return AddProductColumns<M, 3>(ja, jb, b, dst, stride);
    case 6: return AddProductColumns<M, 6>(ja, jb, b, dst, stride);
    case 9: return AddProductColumns<M, 9>(ja, jb, b, dst, stride);
    default: return false;
  }
}

template <int M, int A>
void AddGradientFixed(const double* j, const double* r, double* g) {
  Eigen::Map<Eigen::Matrix<double, A, 1>>(g).noalias() +=
      Eigen::Map<const Eigen::Matrix<double, M, A>>(j).transpose() * Eigen::Map<const Eigen::Matrix<double, M, 1>>(r);
}
template <int M>
bool AddGradientRows(const double* j, int a, const double* r, double* g) {
  switch (a) {
    case 1: AddGradientFixed<M, 1>(j, r, g); return true;
    case 3: AddGradientFixed<M, 3>(j, r, g); return true;
    case 6: AddGradientFixed<M, 6>(j, r, g); return true;
    case 9: AddGradientFixed<M, 9>(j, r, g); return true;
    default: return false;
  }
}

}  // namespace jacobian_products_detail

// dst (ja.cols() x jb.cols(), column stride `stride`) += ja^T jb.
inline void AddJacobianProduct(const Eigen::MatrixXd& ja, const Eigen::MatrixXd& jb, double* dst,
                               std::ptrdiff_t stride) {
  using namespace jacobian_products_detail;
  const int a = static_cast<int>(ja.cols()), b = static_cast<int>(jb.cols());
  if (ja.rows() == 3 && AddProductRows<3>(ja.data(), a, jb.data(), b, dst, stride)) return;
  if (ja.rows() == 4 && AddProductRows<4>(ja.data(), a, jb.data(), b, dst, stride)) return;
  if (ja.rows() == 6 && AddProductRows<6>(ja.data(), a, jb.data(), b, dst, stride)) return;
  Eigen::Map<Eigen::MatrixXd, 0, Eigen::OuterStride<>> block(dst, ja.cols(), jb.cols(), Eigen::OuterStride<>(stride));
  block.noalias() += ja.transpose().lazyProduct(jb);
}

// g (j.cols() entries) += j^T r.
inline void AddJacobianGradient(const Eigen::MatrixXd& j, const Eigen::VectorXd& r, double* g) {
  using namespace jacobian_products_detail;
  const int a = static_cast<int>(j.cols());
  if (j.rows() == 3 && AddGradientRows<3>(j.data(), a, r.data(), g)) return;
  if (j.rows() == 4 && AddGradientRows<4>(j.data(), a, r.data(), g)) return;
  Eigen::Map<Eigen::VectorXd>(g, j.cols()).noalias() += j.transpose() * r;
}

}  // namespace roamlab::estimator::internal
