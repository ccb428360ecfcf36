#include "viewline/tracking/gates.h"

#include <Eigen/Cholesky>
#include <cmath>
#include <sstream>

#include "viewline/core/checks.h"
#include "viewline/core/statistics.h"

namespace viewline::tracking {

const char* toString(GateKind k) {
  switch (k) {
    case GateKind::None: return "none";
    case GateKind::Directional: return "directional";
    case GateKind::Mahalanobis: return "mahalanobis";
  }
  return "?";
}

GateKind gateKindFromString(const std::string& s, const std::string& what) {
  if (s == "none") return GateKind::None;
  if (s == "directional") return GateKind::Directional;
  if (s == "mahalanobis") return GateKind::Mahalanobis;
  throw core::InvalidInput(what + ": '" + s + "' is not a gate (expected none, directional or mahalanobis)");
}

std::string GateReport::reason() const {
  std::ostringstream os;
  if (!rejected) return "accepted";
  if (decided_by == GateKind::Directional)
    os << "directional gate: |d| = " << distance << " > p*sigma = " << directional_threshold;
  else
    os << "mahalanobis gate: d'R^-1 d = " << mahalanobis << " > chi2 = " << chi2_threshold;
  return os.str();
}

namespace {
// χ² quantiles are costly (Boost root finding); cache the last few (m, α) pairs.
double chi2Threshold(Eigen::Index m, double alpha) {
  thread_local Eigen::Index last_m = -1;
  thread_local double last_alpha = -1.0, last_q = 0.0;
  if (m != last_m || alpha != last_alpha) {
    last_q = core::chiSquareQuantile(static_cast<double>(m), 1.0 - alpha);
    last_m = m;
    last_alpha = alpha;
  }
  return last_q;
}
}  // namespace

GateReport evaluateGate(const Eigen::VectorXd& d, const Eigen::MatrixXd& R, const GateConfig& cfg) {
  if (R.rows() != d.size() || R.cols() != d.size()) core::requireSize(R, d.size(), d.size(), "gate: innovation covariance");
  if (!d.allFinite()) core::requireFinite(d, "gate: innovation");
  if (!(cfg.directional_p > 0.0)) throw core::InvalidInput("gate: directional_p must be > 0");
  if (!(cfg.mahalanobis_alpha > 0.0 && cfg.mahalanobis_alpha < 1.0))
    throw core::InvalidInput("gate: mahalanobis_alpha must be in (0, 1)");
  GateReport g;
  g.decided_by = cfg.kind;
  if (d.size() == 0) return g;
  const Eigen::LLT<Eigen::MatrixXd> llt(R);
  if (llt.info() != Eigen::Success) throw core::NumericalError("gate: innovation covariance is not positive definite");
  g.mahalanobis = d.dot(llt.solve(d));
  g.chi2_threshold = chi2Threshold(d.size(), cfg.mahalanobis_alpha);
  g.mahalanobis_outlier = g.mahalanobis > g.chi2_threshold;
  const double dd = d.squaredNorm();
  g.distance = std::sqrt(dd);
  if (dd > 0.0) {
    g.sigma_dir = std::sqrt(d.dot(R * d) / dd);
    g.directional_threshold = cfg.directional_p * g.sigma_dir;
    g.directional_outlier = g.distance > g.directional_threshold;
  }
  switch (cfg.kind) {
    case GateKind::None: g.rejected = false; break;
    case GateKind::Directional: g.rejected = g.directional_outlier; break;
    case GateKind::Mahalanobis: g.rejected = g.mahalanobis_outlier; break;
  }
  return g;
}

}  // namespace viewline::tracking
