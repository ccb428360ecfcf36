#include "viewline/estimation/models/unicycle_predictor.h"

#include <cmath>
#include <sstream>

#include "model_checks.h"

namespace viewline::estimation {

UnicycleTrajectoryPredictor::UnicycleTrajectoryPredictor(std::size_t window) : window_(window) {
  if (window < 2) {
    std::ostringstream s;
    s << "UnicycleTrajectoryPredictor: window = " << window << " (expected >= 2)";
    throw core::InvalidInput(s.str());
  }
}

void UnicycleTrajectoryPredictor::add(double t, double v, double omega) {
  core::requireFinite(t, "UnicycleTrajectoryPredictor::add: t");
  core::requireFinite(v, "UnicycleTrajectoryPredictor::add: v");
  core::requireFinite(omega, "UnicycleTrajectoryPredictor::add: omega");
  if (!samples_.empty() && !(t > samples_.back().t)) {
    std::ostringstream s;
    s << "UnicycleTrajectoryPredictor::add: t = " << t << " (expected > previous " << samples_.back().t << ")";
    throw core::InvalidInput(s.str());
  }
  samples_.push_back({t, v, omega});
  while (samples_.size() > window_) samples_.pop_front();
}

UnicycleTrajectoryPredictor::Accelerations UnicycleTrajectoryPredictor::fitAccelerations() const {
  Accelerations acc;
  if (samples_.size() < 2) return acc;
  // Least squares v_i ≈ v0 + a_v (t_i − t̄) ([K] eq 27): the slope is the covariance ratio.
  const double n = static_cast<double>(samples_.size());
  double tm = 0.0, vm = 0.0, wm = 0.0;
  for (const Sample& s : samples_) {
    tm += s.t;
    vm += s.v;
    wm += s.omega;
  }
  tm /= n;
  vm /= n;
  wm /= n;
  double stt = 0.0, stv = 0.0, stw = 0.0;
  for (const Sample& s : samples_) {
    const double dt = s.t - tm;
    stt += dt * dt;
    stv += dt * (s.v - vm);
    stw += dt * (s.omega - wm);
  }
  acc.a_v = stv / stt;  // stt > 0: times strictly increase
  acc.a_omega = stw / stt;
  return acc;
}

std::vector<Eigen::Vector2d> UnicycleTrajectoryPredictor::predict(const Eigen::VectorXd& x_hat, double T,
                                                                  int m) const {
  return rollForward(x_hat, fitAccelerations(), T, m);
}

std::vector<Eigen::Vector2d> UnicycleTrajectoryPredictor::rollForward(const Eigen::VectorXd& x_hat,
                                                                      const Accelerations& acc, double T, int m) {
  core::requireSize(x_hat, 5, 1, "UnicycleTrajectoryPredictor: state estimate");
  core::requireFinite(x_hat, "UnicycleTrajectoryPredictor: state estimate");
  core::requirePositive(T, "UnicycleTrajectoryPredictor: period T");
  core::requireFinite(acc.a_v, "UnicycleTrajectoryPredictor: a_v");
  core::requireFinite(acc.a_omega, "UnicycleTrajectoryPredictor: a_omega");
  if (m < 1) {
    std::ostringstream s;
    s << "UnicycleTrajectoryPredictor: steps m = " << m << " (expected >= 1)";
    throw core::InvalidInput(s.str());
  }
  std::vector<Eigen::Vector2d> out;
  out.reserve(static_cast<std::size_t>(m));
  Eigen::Vector2d p = x_hat.head<2>();
  for (int h = 0; h < m; ++h) {
    const double ht = h * T;
    const double v = x_hat[3] + acc.a_v * ht;                                   // v(h)
    const double th = x_hat[2] + x_hat[4] * ht + 0.5 * acc.a_omega * ht * ht;  // θ(h)
    p += v * T * Eigen::Vector2d(std::cos(th), std::sin(th));                   // [K] eq 29
    out.push_back(p);
  }
  return out;
}

}  // namespace viewline::estimation
