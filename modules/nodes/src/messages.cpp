#include "viewline/nodes/messages.h"

#include <Eigen/Cholesky>
#include <Eigen/QR>
#include <cmath>

namespace viewline::nodes {

TimeMsg toTimeMsg(core::Timestamp t) {
  const auto ns = static_cast<long long>(std::floor(t * 1e9));
  const long long sec = ns >= 0 ? ns / 1000000000LL : -((-ns + 999999999LL) / 1000000000LL);
  TimeMsg m;
  m.sec = static_cast<std::int32_t>(sec);
  m.nanosec = static_cast<std::uint32_t>(ns - sec * 1000000000LL);
  return m;
}

core::Timestamp fromTimeMsg(const TimeMsg& m) { return static_cast<double>(m.sec) + 1e-9 * m.nanosec; }

void packCovarianceFactor(const Eigen::Matrix<double, 6, 6>& P, double out[21]) {
  Eigen::Matrix<double, 6, 6> L;
  Eigen::LLT<Eigen::Matrix<double, 6, 6>> llt(0.5 * (P + P.transpose()));
  if (llt.info() == Eigen::Success) {
    L = llt.matrixL();
  } else {
    // P = Pᵀ (L D Lᵀ) P with the permutation of the pivoting: L D^½ with D clipped at 0.
    Eigen::LDLT<Eigen::Matrix<double, 6, 6>> ldlt(0.5 * (P + P.transpose()));
    const Eigen::Matrix<double, 6, 1> d = ldlt.vectorD().cwiseMax(0.0).cwiseSqrt();
    Eigen::Matrix<double, 6, 6> F = ldlt.transpositionsP().transpose() *
                                    (Eigen::Matrix<double, 6, 6>(ldlt.matrixL()) * d.asDiagonal());
    // F Fᵀ = P but F is not triangular: its QR gives a triangular factor with the same product.
    Eigen::HouseholderQR<Eigen::Matrix<double, 6, 6>> qr(F.transpose());
    const Eigen::Matrix<double, 6, 6> R = qr.matrixQR().triangularView<Eigen::Upper>();
    L = R.transpose();
  }
  int k = 0;
  for (int r = 0; r < 6; ++r)
    for (int c = 0; c <= r; ++c) out[k++] = L(r, c);
}

Eigen::Matrix<double, 6, 6> unpackCovarianceFactor(const double in[21]) {
  Eigen::Matrix<double, 6, 6> L = Eigen::Matrix<double, 6, 6>::Zero();
  int k = 0;
  for (int r = 0; r < 6; ++r)
    for (int c = 0; c <= r; ++c) L(r, c) = in[k++];
  return L * L.transpose();
}

}  // namespace viewline::nodes
