#include "viewline/estimation/imm.h"

#include <Eigen/Cholesky>
#include <cmath>
#include <limits>

#include "viewline/core/checks.h"
#include "viewline/core/error.h"

namespace viewline::estimation {

namespace {
constexpr double kLog2Pi = 1.8378770664093453;

Eigen::MatrixXd symmetrize(const Eigen::MatrixXd& P) { return 0.5 * (P + P.transpose()); }

// Moment-matched mixture of (x_i, P_i) with weights w (sum 1).
void mixture(const std::vector<Eigen::VectorXd>& xs, const std::vector<Eigen::MatrixXd>& Ps, const Eigen::VectorXd& w,
             Eigen::VectorXd& x, Eigen::MatrixXd& P) {
  x = Eigen::VectorXd::Zero(xs.front().size());
  for (std::size_t i = 0; i < xs.size(); ++i) x += w(static_cast<Eigen::Index>(i)) * xs[i];
  P = Eigen::MatrixXd::Zero(x.size(), x.size());
  for (std::size_t i = 0; i < xs.size(); ++i) {
    const Eigen::VectorXd d = xs[i] - x;
    P += w(static_cast<Eigen::Index>(i)) * (Ps[i] + d * d.transpose());
  }
  P = symmetrize(P);
}
}  // namespace

Imm::Imm(std::vector<ImmMode> modes, Eigen::MatrixXd jump) : modes_(std::move(modes)), jump_(std::move(jump)) {
  const auto M = static_cast<Eigen::Index>(modes_.size());
  if (M < 1) throw core::InvalidInput("Imm: at least one mode");
  for (const auto& m : modes_) {
    if (!m.transition) throw core::InvalidInput("Imm: mode '" + m.name + "' has no transition");
    core::requirePositive(m.sojourn, "Imm: mode '" + m.name + "' sojourn");
  }
  if (jump_.size() == 0) {
    jump_ = Eigen::MatrixXd::Constant(M, M, M > 1 ? 1.0 / static_cast<double>(M - 1) : 0.0);
    jump_.diagonal().setZero();
  }
  if (jump_.rows() != M || jump_.cols() != M) throw core::InvalidInput("Imm: jump matrix must be M x M");
  for (Eigen::Index i = 0; i < M; ++i) {
    if (jump_(i, i) != 0.0) throw core::InvalidInput("Imm: jump matrix diagonal must be zero");
    if ((jump_.row(i).array() < 0.0).any()) throw core::InvalidInput("Imm: jump matrix entries must be >= 0");
    if (M > 1 && std::abs(jump_.row(i).sum() - 1.0) > 1e-9) throw core::InvalidInput("Imm: jump matrix rows must sum to 1");
  }
}

Eigen::MatrixXd Imm::switching(double dt) const {
  const auto M = static_cast<Eigen::Index>(modes_.size());
  Eigen::MatrixXd Pi = Eigen::MatrixXd::Zero(M, M);
  for (Eigen::Index i = 0; i < M; ++i) {
    const double stay = M > 1 ? std::exp(-dt / modes_[static_cast<std::size_t>(i)].sojourn) : 1.0;
    Pi.row(i) = (1.0 - stay) * jump_.row(i);
    Pi(i, i) = stay;
  }
  return Pi;
}

void Imm::reset(const Eigen::VectorXd& x, const Eigen::MatrixXd& P, core::Timestamp t, const Eigen::VectorXd& mu0) {
  const auto M = static_cast<Eigen::Index>(modes_.size());
  states_.assign(modes_.size(), StateEstimate(x, P, t));
  if (mu0.size() == 0) {
    mu_ = Eigen::VectorXd::Constant(M, 1.0 / static_cast<double>(M));
  } else {
    if (mu0.size() != M || (mu0.array() < 0.0).any() || !(mu0.sum() > 0.0)) {
      throw core::InvalidInput("Imm::reset: mu0 must have M non-negative entries with a positive sum");
    }
    mu_ = mu0 / mu0.sum();
  }
}

core::Timestamp Imm::time() const {
  if (states_.empty()) throw core::Error("Imm: not initialised");
  return states_.front().t();
}

void Imm::predict(core::Timestamp t) {
  if (states_.empty()) throw core::Error("Imm::predict: not initialised");
  const double dt = t - time();
  if (!(dt > 1e-12)) return;
  const std::size_t M = modes_.size();
  const Eigen::MatrixXd Pi = switching(dt);
  const Eigen::VectorXd c = Pi.transpose() * mu_;
  std::vector<Eigen::VectorXd> xs(M);
  std::vector<Eigen::MatrixXd> Ps(M);
  for (std::size_t i = 0; i < M; ++i) {
    xs[i] = states_[i].x();
    Ps[i] = states_[i].P();
  }
  std::vector<StateEstimate> next;
  next.reserve(M);
  for (std::size_t j = 0; j < M; ++j) {
    const auto jj = static_cast<Eigen::Index>(j);
    Eigen::VectorXd w(static_cast<Eigen::Index>(M));
    for (std::size_t i = 0; i < M; ++i) w(static_cast<Eigen::Index>(i)) = Pi(static_cast<Eigen::Index>(i), jj) * mu_(static_cast<Eigen::Index>(i));
    if (c(jj) > 1e-300) w /= c(jj); else w = Eigen::VectorXd::Unit(static_cast<Eigen::Index>(M), jj);
    Eigen::VectorXd x0;
    Eigen::MatrixXd P0;
    mixture(xs, Ps, w, x0, P0);
    StateEstimate s(x0, P0, time());
    NonlinearTransition tr = modes_[j].transition(dt);
    tr.dt = dt;
    ekfPredict(s, tr);
    s.setTime(t);
    next.push_back(std::move(s));
  }
  states_ = std::move(next);
  mu_ = c / c.sum();
}

double Imm::combinedNis(const LinearMeasurement& m) const {
  const StateEstimate s = combined();
  const Eigen::MatrixXd S = innovationCovariance(s, m.C, m.R);
  const Eigen::VectorXd d = m.y - m.C * s.x();
  return d.dot(S.ldlt().solve(d));
}

Imm::Report Imm::update(const LinearMeasurement& m) {
  if (states_.empty()) throw core::Error("Imm::update: not initialised");
  Report r;
  r.nis = combinedNis(m);
  const auto M = static_cast<Eigen::Index>(modes_.size());
  Eigen::VectorXd logw(M);
  for (Eigen::Index j = 0; j < M; ++j) {
    auto& s = states_[static_cast<std::size_t>(j)];
    const UpdateReport u = estimation::update(s, m);
    const Eigen::LLT<Eigen::MatrixXd> llt(u.S);
    const double logdet = 2.0 * llt.matrixL().toDenseMatrix().diagonal().array().log().sum();
    const double loglik = -0.5 * (u.nis + logdet + static_cast<double>(u.S.rows()) * kLog2Pi);
    logw(j) = (mu_(j) > 0.0 ? std::log(mu_(j)) : -std::numeric_limits<double>::infinity()) + loglik;
  }
  const double mx = logw.maxCoeff();
  Eigen::VectorXd w = (logw.array() - mx).exp();
  const double sum = w.sum();
  r.log_likelihood = mx + std::log(sum);
  mu_ = w / sum;
  // Keep every mode reachable (no probability collapses to exactly zero).
  mu_ = (mu_.array().max(1e-12)).matrix();
  mu_ /= mu_.sum();
  return r;
}

StateEstimate Imm::combined() const {
  if (states_.empty()) throw core::Error("Imm::combined: not initialised");
  std::vector<Eigen::VectorXd> xs;
  std::vector<Eigen::MatrixXd> Ps;
  for (const auto& s : states_) {
    xs.push_back(s.x());
    Ps.push_back(s.P());
  }
  Eigen::VectorXd x;
  Eigen::MatrixXd P;
  mixture(xs, Ps, mu_, x, P);
  return StateEstimate(x, P, time());
}

}  // namespace viewline::estimation
