#pragma once
// Fixed-size path of the linear square-root Kalman filter (kalman_filter.h) for small states
// whose sizes are known at compile time (e.g. the 6-state ballistic filter with the 2 viewline
// rows of one image): the same equations and the same validation on Eigen fixed-size matrices,
// so nothing is allocated and the loops have compile-time bounds.
//
//   Time update ([L] eqs 1-10):  L⁺ = chol((Φ L)(Φ L)ᵀ + Q)  (or [Φ L  Gq] Θ = [L⁺ 0] when that
//                                is only semi-definite),  x ← Φ x + Γ u
//   Measurement update (filter form):
//       [ C L   Ge ] Θ = [ S^½  0  ]     S^½ S^½ᵀ = R + C P Cᵀ,  w = S^-½ (y − C x),
//       [ L     0  ]     [ K̄    L⁺ ]     x ← x + K̄ w,  NIS = |w|²
//   with Gq Gqᵀ = Q, Ge Geᵀ = R (Cholesky), Θ orthogonal (Householder reflections from the right).
//
// Validation, on every call as in the dynamic path: finite Φ, Γ, u, C, y; dt finite and >= 0;
// Q finite, symmetric (|Q − Qᵀ| <= 1e-9 max(1, max|Q|)) and positive semi-definite; R finite,
// symmetric and positive definite; a non-finite result throws core::NumericalError and leaves
// the state unchanged. As in the dynamic path the factor of a covariance bit-for-bit equal to the
// one validated by the previous call of this thread (per size) is reused. The dynamic path's
// messages are used (core::InvalidInput naming the quantity).
//
// Results equal the dynamic path's to rounding (the time update factors P⁺ by Cholesky instead
// of QR; the fixed-size products may sum in another order): the tests compare them to 1e-12 relative.

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <algorithm>
#include <cmath>

#include "viewline/core/error.h"
#include "viewline/core/time.h"
#include "viewline/estimation/state.h"

namespace viewline::estimation {

/// Mean and lower-triangular covariance factor (P = L Lᵀ) of an N-state, at time t.
template <int N>
struct FixedEstimate {
  Eigen::Matrix<double, N, 1> x = Eigen::Matrix<double, N, 1>::Zero();  ///< mean
  Eigen::Matrix<double, N, N> L = Eigen::Matrix<double, N, N>::Zero();  ///< lower-triangular factor of P
  core::Timestamp t = 0.0;                                              ///< s

  /// The covariance P = L Lᵀ.
  Eigen::Matrix<double, N, N> P() const { return L * L.transpose(); }
  /// From a dynamic estimate of dimension N (throws core::InvalidInput otherwise).
  static FixedEstimate fromState(const StateEstimate& s) {
    if (s.dim() != N) throw core::InvalidInput("FixedEstimate: state dimension differs from the fixed size");
    FixedEstimate f;
    f.x = s.x();
    f.L = s.sqrtP();
    f.t = s.t();
    return f;
  }
  /// The same estimate as a dynamic StateEstimate.
  StateEstimate toState() const { return StateEstimate::fromSqrt(x, L, t); }
};

/// x ← Φ x + Γ u + v, cov v = Q, over dt seconds (P inputs; P = 0: no input).
template <int N, int P>
struct FixedTransition {
  Eigen::Matrix<double, N, N> Phi = Eigen::Matrix<double, N, N>::Identity();  ///< transition Φ
  Eigen::Matrix<double, N, P> Gamma = Eigen::Matrix<double, N, P>::Zero();     ///< input matrix Γ
  Eigen::Matrix<double, P, 1> u = Eigen::Matrix<double, P, 1>::Zero();         ///< input u
  Eigen::Matrix<double, N, N> Q = Eigen::Matrix<double, N, N>::Zero();         ///< process noise (PSD)
  double dt = 0.0;                                                             ///< s, >= 0
};

/// y = C x + e, cov e = R, M rows.
template <int N, int M>
struct FixedMeasurement {
  Eigen::Matrix<double, M, N> C = Eigen::Matrix<double, M, N>::Zero();      ///< measurement matrix
  Eigen::Matrix<double, M, 1> y = Eigen::Matrix<double, M, 1>::Zero();      ///< measurement
  Eigen::Matrix<double, M, M> R = Eigen::Matrix<double, M, M>::Identity();  ///< noise (positive definite)
};

/// What an update saw (as UpdateReport, fixed size).
template <int M>
struct FixedUpdateReport {
  Eigen::Matrix<double, M, 1> innovation = Eigen::Matrix<double, M, 1>::Zero();  ///< d = y − C x(k|k−1)
  Eigen::Matrix<double, M, M> S = Eigen::Matrix<double, M, M>::Zero();           ///< R + C P Cᵀ
  double nis = 0.0;                                                              ///< dᵀ S⁻¹ d
};

namespace fixed_detail {

/// Throws core::InvalidInput: matrix `what` has NaN or Inf (the dynamic path's message).
[[noreturn]] void throwNotFinite(const char* what);
/// Throws core::InvalidInput: scalar `what` is NaN or Inf.
[[noreturn]] void throwNotFiniteScalar(const char* what);
/// Throws core::InvalidInput: covariance `what` is not symmetric positive (semi-)definite.
[[noreturn]] void throwBadCovariance(const Eigen::MatrixXd& M, const char* what, bool definite);
/// Throws core::InvalidInput: transition dt < 0.
[[noreturn]] void throwNegativeDt();
/// Throws core::NumericalError: `step` (predict or update) produced NaN or Inf.
[[noreturn]] void throwNonFiniteResult(const char* step);
/// Throws core::NumericalError: the innovation covariance factor has a zero pivot.
[[noreturn]] void throwSingularInnovation();

/// Factor of a positive semi-definite (not definite) matrix, as psdSqrt (square_root.h).
Eigen::MatrixXd psdFactor(const Eigen::MatrixXd& M, const char* what);

/// Same rule as core::isSymmetric plus finiteness, one pass.
template <typename Mat>
bool finiteAndSymmetric(const Mat& m) {
  double scale = 1.0, asym = 0.0;
  for (Eigen::Index j = 0; j < m.cols(); ++j) {
    for (Eigen::Index i = 0; i < m.rows(); ++i) {
      const double a = m(i, j);
      if (!std::isfinite(a)) return false;
      scale = std::max(scale, std::abs(a));
      if (i > j) asym = std::max(asym, std::abs(a - m(j, i)));
    }
  }
  return asym <= 1e-9 * scale;
}

/// A validated covariance and its factor, per thread, size and role (0: Q, 1: R).
template <int K, int Role>
struct FactorCache {
  Eigen::Matrix<double, K, K> M;  ///< the covariance validated last
  Eigen::Matrix<double, K, K> G;  ///< its factor, G Gᵀ = M
  bool valid = false;             ///< M and G hold a validated pair
};

/// Square-root factor G (G Gᵀ = M) of a validated covariance (see the file comment).
template <int K, int Role>
const Eigen::Matrix<double, K, K>& validatedFactor(const Eigen::Matrix<double, K, K>& M, const char* what,
                                                   bool definite) {
  thread_local FactorCache<K, Role> cache;
  if (cache.valid && std::equal(M.data(), M.data() + M.size(), cache.M.data())) return cache.G;
  cache.valid = false;
  if (!finiteAndSymmetric(M)) throwBadCovariance(M, what, definite);
  Eigen::LLT<Eigen::Matrix<double, K, K>> llt(M);
  if (llt.info() == Eigen::Success) {
    cache.G = llt.matrixL();
  } else {
    if (definite) throwBadCovariance(M, what, true);
    cache.G = Eigen::Matrix<double, K, K>(psdFactor(M, what));
  }
  cache.M = M;
  cache.valid = true;
  return cache.G;
}

/// lowerTriangularizeInPlace (square_root.h) on a fixed-size row-major array: A ← A Θ with
/// A(:, 0:min(r,c)) lower triangular, non-negative diagonal, the other columns zero.
template <int R, int C>
void lowerTriangularize(Eigen::Matrix<double, R, C, Eigen::RowMajor>& A) {
  constexpr int k = R < C ? R : C;
  for (int i = 0; i < k; ++i) {
    double tail = 0.0;
    for (int j = i + 1; j < C; ++j) tail += A(i, j) * A(i, j);
    if (tail > 0.0) {
      // Householder H = I − β v vᵀ with x H = α e₁: α = −sign(x₀) σ, v = x − α e₁,
      // β = 1 / (σ (σ + |x₀|)) (no cancellation).
      const double x0 = A(i, i);
      const double sigma = std::sqrt(x0 * x0 + tail);
      const double alpha = (x0 > 0.0) ? -sigma : sigma;
      const double beta = 1.0 / (sigma * (sigma + std::abs(x0)));
      A(i, i) = x0 - alpha;  // row i now holds v from column i on
      for (int r = i + 1; r < R; ++r) {
        double dot = 0.0;
        for (int j = i; j < C; ++j) dot += A(r, j) * A(i, j);
        const double w = beta * dot;
        for (int j = i; j < C; ++j) A(r, j) -= w * A(i, j);
      }
      A(i, i) = alpha;
      for (int j = i + 1; j < C; ++j) A(i, j) = 0.0;
    }
    if (A(i, i) < 0.0)
      for (int r = i; r < R; ++r) A(r, i) = -A(r, i);
  }
}

}  // namespace fixed_detail

/// Time update x ← Φ x + Γ u, P ← Φ P Φᵀ + Q, t ← t + dt (validated, see the file comment).
template <int N, int P>
void predict(FixedEstimate<N>& s, const FixedTransition<N, P>& tr) {
  if (!tr.Phi.allFinite()) fixed_detail::throwNotFinite("transition Phi");
  const auto& Gq = fixed_detail::validatedFactor<N, 0>(tr.Q, "process noise Q (R1)", false);
  if (!std::isfinite(tr.dt)) fixed_detail::throwNotFiniteScalar("transition dt");
  if (tr.dt < 0.0) fixed_detail::throwNegativeDt();
  if constexpr (P > 0) {
    if (!tr.Gamma.allFinite()) fixed_detail::throwNotFinite("input matrix Gamma");
    if (!tr.u.allFinite()) fixed_detail::throwNotFinite("input u");
  }
  Eigen::Matrix<double, N, 1> x = tr.Phi * s.x;
  if constexpr (P > 0) x.noalias() += tr.Gamma * tr.u;
  // Plain (lazy, unrolled) products: Eigen's triangular and rank-update kernels are blocked for
  // large matrices and cost more than they save at these sizes.
  const Eigen::Matrix<double, N, N> phiL = (tr.Phi * s.L).eval();
  // P⁺ = (Φ L)(Φ L)ᵀ + Q is a sum of positive semi-definite terms (no cancellation, unlike the
  // measurement update), so its Cholesky factor is as accurate as the QR of [Φ L  Gq] and costs
  // a third. When P⁺ is only semi-definite the array algorithm gives the factor.
  Eigen::Matrix<double, N, N> Pplus = tr.Q;
  Pplus.noalias() += (phiL * phiL.transpose()).eval();
  Eigen::LLT<Eigen::Matrix<double, N, N>> llt(Pplus);
  Eigen::Matrix<double, N, N> L;
  if (llt.info() == Eigen::Success) {
    L = llt.matrixL();
  } else {
    Eigen::Matrix<double, N, 2 * N, Eigen::RowMajor> pre;
    pre.template leftCols<N>() = phiL;
    pre.template rightCols<N>() = Gq;
    fixed_detail::lowerTriangularize(pre);
    L = pre.template leftCols<N>();
  }
  if (!x.allFinite() || !L.allFinite()) fixed_detail::throwNonFiniteResult("predict");
  s.x = x;
  s.L = L;
  s.t += tr.dt;
}

/// Measurement update (filter form), validated; returns innovation, S and NIS.
template <int N, int M>
FixedUpdateReport<M> update(FixedEstimate<N>& s, const FixedMeasurement<N, M>& m) {
  if (!m.C.allFinite()) fixed_detail::throwNotFinite("measurement matrix C");
  if (!m.y.allFinite()) fixed_detail::throwNotFinite("measurement y");
  const auto& Ge = fixed_detail::validatedFactor<M, 1>(m.R, "measurement noise R (R2)", true);
  Eigen::Matrix<double, M + N, N + M, Eigen::RowMajor> pre;
  pre.template topLeftCorner<M, N>() = (m.C * s.L).eval();
  pre.template topRightCorner<M, M>() = Ge;
  pre.template bottomLeftCorner<N, N>() = s.L;
  pre.template bottomRightCorner<N, M>().setZero();
  fixed_detail::lowerTriangularize(pre);
  const auto sqrtS = pre.template topLeftCorner<M, M>();
  if ((sqrtS.diagonal().array() <= 0.0).any()) fixed_detail::throwSingularInnovation();
  FixedUpdateReport<M> rep;
  rep.innovation = m.y;
  rep.innovation.noalias() -= m.C * s.x;
  rep.S.noalias() = sqrtS * sqrtS.transpose();
  Eigen::Matrix<double, M, 1> w = rep.innovation;
  sqrtS.template triangularView<Eigen::Lower>().solveInPlace(w);
  rep.nis = w.squaredNorm();
  Eigen::Matrix<double, N, 1> x = s.x;
  x.noalias() += pre.template bottomLeftCorner<N, M>() * w;
  const Eigen::Matrix<double, N, N> L = pre.template block<N, N>(M, M);
  if (!x.allFinite() || !L.allFinite()) fixed_detail::throwNonFiniteResult("update");
  s.x = x;
  s.L = L;
  return rep;
}

}  // namespace viewline::estimation
