// Constants and helpers shared by the translation units of NormalEquations (normal_equations.h):
// normal_equations.cc (Reset: the blocks, the included factors and H's pattern; Update), normal_equations_linearize.cc
// (Linearize: H, g and the cost from the factors, with the fixed-size J^T J kernels) and normal_equations_factorize.cc
// (Solve, Covariance, BorderInformation: CHOLMOD or the envelope factorization, with its band kernels).
#pragma once

#include <cstddef>

#include <Eigen/CholmodSupport>
#include <Eigen/SparseCore>

#include "estimator/internal/normal_equations.h"

namespace roamlab::estimator::internal {

// Systems up to this dimension (a tracking window) are factored in their envelope when in natural order (Reset),
// otherwise by CHOLMOD's simplicial LLT; larger ones (whole recordings) in their envelope when it is narrow, otherwise
// by CHOLMOD's supernodal LLT, whose dense BLAS kernels pay off only on large supernodes.
inline constexpr int kMaxSimplicialDimension = 2000;

// A large system in natural order is factored in its envelope when the envelope has at most this many times the
// entries of H's upper triangle (NormalEquations::EnvelopeIsNarrow).
inline constexpr std::size_t kMaxEnvelopeOverPattern = 2;

// Widest dense border of a natural-order system (NormalEquations::FactorEnvelope); columns beyond it stay in the
// envelope.
inline constexpr int kMaxBorder = 128;

// Up to this many columns, a natural-order system's covariance is Y^T Y from the forward substitution alone (the
// product costs columns^2 x dimension, a back substitution columns x the factor's size).
inline constexpr int kMaxForwardCovarianceColumns = 16;

// Block patterns of H kept for a small system whose pattern comes back as it slides (NormalEquations::BuildPattern):
// a window's instances of a parameter per 0.1 s repeat every ten poses.
inline constexpr std::size_t kPatternCache = 16;

// How far a pass over a whole recording's factors or variables prefetches ahead: their data lie in heap blocks of their
// own, whose addresses the hardware's prefetcher cannot follow.
inline constexpr std::size_t kPrefetchAhead = 8;  // factors or variables

// H holds the block upper triangle with full diagonal blocks; CHOLMOD (stype = upper) reads only entries on and above
// the diagonal, and so does selfadjointView<Upper>().
struct NormalEquations::Cholmod {
  Eigen::CholmodDecomposition<Eigen::SparseMatrix<double>, Eigen::Upper> llt;
  Eigen::SparseMatrix<double> damped;
  bool analyzed = false;
  bool factored_undamped = false;  // the factorization is of H itself, at the last linearization
};

// The positions i < n with block[i] >= 0 (a factor's free variables), in order, into free; returns their count. The
// normal equations visit a factor's (a, b) pairs of free variables in this order, a outer, b inner.
inline int FreePositions(const int* block, int n, int* free) {
  int count = 0;
  for (int i = 0; i < n; ++i)
    if (block[i] >= 0) free[count++] = i;
  return count;
}

}  // namespace roamlab::estimator::internal
