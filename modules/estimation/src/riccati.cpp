#include "viewline/estimation/riccati.h"

#include <Eigen/Cholesky>
#include <Eigen/LU>

#include "viewline/core/checks.h"

namespace viewline::estimation {

StationaryFilter solveDare(const Eigen::MatrixXd& A, const Eigen::MatrixXd& C, const Eigen::MatrixXd& Q,
                           const Eigen::MatrixXd& R, int max_iterations, double tol) {
  const Eigen::Index n = A.rows();
  const Eigen::Index m = C.rows();
  core::requireSize(A, n, n, "DARE A");
  core::requireFinite(A, "DARE A");
  core::requireSize(C, m, n, "DARE C");
  core::requireFinite(C, "DARE C");
  core::requireSize(Q, n, n, "DARE Q");
  core::requireSymmetricPositiveSemiDefinite(Q, "DARE Q");
  core::requireSize(R, m, m, "DARE R");
  core::requireSymmetricPositiveDefinite(R, "DARE R");

  const Eigen::LLT<Eigen::MatrixXd> rllt(R);
  Eigen::MatrixXd Ak = A.transpose();
  Eigen::MatrixXd Gk = C.transpose() * rllt.solve(C);
  Eigen::MatrixXd Hk = Q;
  const Eigen::MatrixXd I = Eigen::MatrixXd::Identity(n, n);

  StationaryFilter out;
  for (int k = 0; k < max_iterations; ++k) {
    const Eigen::PartialPivLU<Eigen::MatrixXd> W(I + Gk * Hk);
    const Eigen::MatrixXd WiA = W.solve(Ak);
    const Eigen::MatrixXd WiG = W.solve(Gk);
    const Eigen::MatrixXd Hn = Hk + Ak.transpose() * Hk * WiA;
    const Eigen::MatrixXd Gn = Gk + Ak * WiG * Ak.transpose();
    const Eigen::MatrixXd An = Ak * WiA;
    const double change = (Hn - Hk).cwiseAbs().maxCoeff() / std::max(1.0, Hn.cwiseAbs().maxCoeff());
    Hk = 0.5 * (Hn + Hn.transpose());
    Gk = 0.5 * (Gn + Gn.transpose());
    Ak = An;
    out.iterations = k + 1;
    if (!Hk.allFinite()) break;
    if (change < tol) break;
  }
  if (!Hk.allFinite()) throw core::NumericalError("DARE: doubling diverged (is (A, C) detectable?)");

  const Eigen::MatrixXd& P = Hk;
  const Eigen::MatrixXd S = C * P * C.transpose() + R;
  const Eigen::LLT<Eigen::MatrixXd> sllt(S);
  const Eigen::MatrixXd PCt = P * C.transpose();
  const Eigen::MatrixXd Kf = sllt.solve(PCt.transpose()).transpose();
  const Eigen::MatrixXd rhs = A * P * A.transpose() + Q - A * PCt * sllt.solve(PCt.transpose()) * A.transpose();
  out.residual = (rhs - P).cwiseAbs().maxCoeff() / std::max(1.0, P.cwiseAbs().maxCoeff());
  if (out.residual > 1e-8) {
    throw core::NumericalError("DARE: no stabilising solution found (residual " +
                               std::to_string(out.residual) + ")");
  }
  out.P = P;
  out.Kf = Kf;
  out.Pf = P - Kf * C * P;
  core::symmetrize(out.Pf);
  return out;
}

}  // namespace viewline::estimation
