#include "viewline/estimation/models/coordinated_turn.h"

#include <cmath>

#include "viewline/core/checks.h"
#include "viewline/core/error.h"

namespace viewline::estimation::models {

void CoordinatedTurnParams::validate() const {
  if (!(q_accel >= 0.0) || !std::isfinite(q_accel)) throw core::InvalidInput("coordinated_turn.q_accel must be >= 0");
  if (!(q_omega >= 0.0) || !std::isfinite(q_omega)) throw core::InvalidInput("coordinated_turn.q_omega must be >= 0");
}

namespace {
void checkState(const Eigen::VectorXd& x, double dt) {
  if (x.size() != 5) throw core::InvalidInput("coordinated turn: state must have 5 entries (px, py, vx, vy, omega)");
  core::requireFinite(x, "coordinated turn: x");
  if (!(dt >= 0.0) || !std::isfinite(dt)) throw core::InvalidInput("coordinated turn: dt must be >= 0");
}

// a = sin(wT)/w, b = (1 − cos wT)/w and their derivatives da/dw, db/dw.
struct Coeffs {
  double s, c, a, b, da, db;
};
Coeffs coeffs(double w, double T) {
  Coeffs k{};
  const double wT = w * T;
  k.s = std::sin(wT);
  k.c = std::cos(wT);
  if (std::abs(wT) < 1e-4) {
    const double T2 = T * T, T3 = T2 * T, T4 = T3 * T;
    k.a = T - w * w * T3 / 6.0;
    k.b = w * T2 / 2.0 - w * w * w * T4 / 24.0;
    k.da = -w * T3 / 3.0;
    k.db = T2 / 2.0 - w * w * T4 / 8.0;
  } else {
    k.a = k.s / w;
    k.b = (1.0 - k.c) / w;
    k.da = (T * k.c - k.a) / w;   // d/dw (s/w) = (T c w − s)/w²
    k.db = (T * k.s - k.b) / w;   // d/dw ((1 − c)/w) = (T s w − (1 − c))/w²
  }
  return k;
}
}  // namespace

Eigen::VectorXd coordinatedTurnStep(const Eigen::VectorXd& x, double dt) {
  checkState(x, dt);
  const Coeffs k = coeffs(x(4), dt);
  const double vx = x(2), vy = x(3);
  Eigen::VectorXd y(5);
  y << x(0) + k.a * vx - k.b * vy, x(1) + k.b * vx + k.a * vy, k.c * vx - k.s * vy, k.s * vx + k.c * vy, x(4);
  return y;
}

Eigen::MatrixXd coordinatedTurnJacobian(const Eigen::VectorXd& x, double dt) {
  checkState(x, dt);
  const Coeffs k = coeffs(x(4), dt);
  const double vx = x(2), vy = x(3);
  Eigen::MatrixXd F = Eigen::MatrixXd::Identity(5, 5);
  F(0, 2) = k.a;
  F(0, 3) = -k.b;
  F(1, 2) = k.b;
  F(1, 3) = k.a;
  F(2, 2) = k.c;
  F(2, 3) = -k.s;
  F(3, 2) = k.s;
  F(3, 3) = k.c;
  F(0, 4) = k.da * vx - k.db * vy;
  F(1, 4) = k.db * vx + k.da * vy;
  F(2, 4) = -dt * k.s * vx - dt * k.c * vy;
  F(3, 4) = dt * k.c * vx - dt * k.s * vy;
  return F;
}

Eigen::MatrixXd coordinatedTurnNoise(const CoordinatedTurnParams& p, double dt) {
  p.validate();
  Eigen::MatrixXd Q = Eigen::MatrixXd::Zero(5, 5);
  const double T = dt, T2 = T * T, T3 = T2 * T;
  for (int i = 0; i < 2; ++i) {
    Q(i, i) = p.q_accel * T3 / 3.0;
    Q(i, i + 2) = Q(i + 2, i) = p.q_accel * T2 / 2.0;
    Q(i + 2, i + 2) = p.q_accel * T;
  }
  Q(4, 4) = p.q_omega * T;
  return Q;
}

NonlinearTransition coordinatedTurnTransition(const CoordinatedTurnParams& p, double dt) {
  NonlinearTransition tr;
  tr.f = [dt](const Eigen::VectorXd& x) { return coordinatedTurnStep(x, dt); };
  tr.F = [dt](const Eigen::VectorXd& x) { return coordinatedTurnJacobian(x, dt); };
  tr.Q = coordinatedTurnNoise(p, dt);
  tr.dt = dt;
  return tr;
}

}  // namespace viewline::estimation::models
