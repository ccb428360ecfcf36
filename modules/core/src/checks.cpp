#include "viewline/core/checks.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <cmath>
#include <sstream>

namespace viewline::core {

namespace {
std::string shape(const Eigen::Ref<const Eigen::MatrixXd>& m) {
  std::ostringstream s;
  s << m.rows() << "x" << m.cols();
  return s.str();
}
}  // namespace

void requireFinite(const Eigen::Ref<const Eigen::MatrixXd>& m, const std::string& what) {
  if (!m.allFinite()) {
    throw InvalidInput(what + " contains NaN or Inf (expected finite values)");
  }
}

void requireFinite(double value, const std::string& what) {
  if (!std::isfinite(value)) {
    throw InvalidInput(what + " is NaN or Inf (expected a finite value)");
  }
}

void requirePositive(double value, const std::string& what) {
  requireFinite(value, what);
  if (!(value > 0.0)) {
    std::ostringstream s;
    s << what << " = " << value << " (expected > 0)";
    throw InvalidInput(s.str());
  }
}

void requireNonNegative(double value, const std::string& what) {
  requireFinite(value, what);
  if (value < 0.0) {
    std::ostringstream s;
    s << what << " = " << value << " (expected >= 0)";
    throw InvalidInput(s.str());
  }
}

void requireSize(const Eigen::Ref<const Eigen::MatrixXd>& m, Eigen::Index rows, Eigen::Index cols,
                 const std::string& what) {
  if (m.rows() != rows || m.cols() != cols) {
    std::ostringstream s;
    s << what << " is " << shape(m) << " (expected " << rows << "x" << cols << ")";
    throw InvalidInput(s.str());
  }
}

bool isSymmetric(const Eigen::Ref<const Eigen::MatrixXd>& m, double rel_tol) {
  if (m.rows() != m.cols()) return false;
  if (m.size() == 0) return true;
  const double scale = std::max(1.0, m.cwiseAbs().maxCoeff());
  return (m - m.transpose()).cwiseAbs().maxCoeff() <= rel_tol * scale;
}

void symmetrize(Eigen::MatrixXd& m) {
  m = 0.5 * (m + m.transpose()).eval();
}

void requireSymmetricPositiveDefinite(const Eigen::Ref<const Eigen::MatrixXd>& m,
                                      const std::string& what, double rel_tol) {
  if (m.rows() != m.cols()) throw InvalidInput(what + " is " + shape(m) + " (expected square)");
  requireFinite(m, what);
  if (!isSymmetric(m, rel_tol)) throw InvalidInput(what + " is not symmetric");
  if (m.size() == 0) return;
  Eigen::LLT<Eigen::MatrixXd> llt(m);
  if (llt.info() != Eigen::Success) throw InvalidInput(what + " is not positive definite");
}

void requireSymmetricPositiveSemiDefinite(const Eigen::Ref<const Eigen::MatrixXd>& m,
                                          const std::string& what, double rel_tol) {
  if (m.rows() != m.cols()) throw InvalidInput(what + " is " + shape(m) + " (expected square)");
  requireFinite(m, what);
  if (!isSymmetric(m, rel_tol)) throw InvalidInput(what + " is not symmetric");
  if (m.size() == 0) return;
  Eigen::LDLT<Eigen::MatrixXd> ldlt(m);
  const double scale = std::max(m.diagonal().cwiseAbs().maxCoeff(), 1e-300);
  if (ldlt.info() == Eigen::Success && (ldlt.vectorD().array() >= -rel_tol * scale).all()) return;
  // Eigen's LDLT reports NumericalIssue when an exactly zero pivot comes before a nonzero one,
  // which a rank-deficient PSD matrix can give (e.g. a rank-2 noise block G Σ Gᵀ beside a
  // smaller diagonal entry): decide on the eigenvalues then (the fast path above is the usual one).
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(m, Eigen::EigenvaluesOnly);
  if (eig.info() != Eigen::Success || eig.eigenvalues().minCoeff() < -rel_tol * scale)
    throw InvalidInput(what + " is not positive semi-definite");
}

}  // namespace viewline::core
