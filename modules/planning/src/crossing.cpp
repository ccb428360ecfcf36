#include "viewline/planning/crossing.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "viewline/core/error.h"
#include "viewline/estimation/models/ballistic_drag.h"

namespace viewline::planning {

using core::InvalidInput;
using Vector6 = Eigen::Matrix<double, 6, 1>;
using Matrix6 = Eigen::Matrix<double, 6, 6>;

const char* toString(FlightModel m) { return m == FlightModel::Ballistic ? "ballistic" : "drag"; }

void CrossingModel::validate() const {
  if (!gravity_w.allFinite()) throw InvalidInput("planner.gravity: expected finite values");
  if (!(std::isfinite(drag_k) && drag_k >= 0.0)) throw InvalidInput("planner.drag_k: expected a finite value >= 0");
  if (!(std::isfinite(accel_psd) && accel_psd >= 0.0))
    throw InvalidInput("planner.accel_psd: expected a finite value >= 0");
  if (!(std::isfinite(max_horizon) && max_horizon > 0.0))
    throw InvalidInput("planner.max_horizon_s: expected a positive value");
  if (!(std::isfinite(step) && step > 0.0)) throw InvalidInput("planner.step_s: expected a positive value");
}

double Crossing::sigmaMax() const {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(0.5 * (cov_p + cov_p.transpose()), Eigen::EigenvaluesOnly);
  return std::sqrt(std::max(0.0, es.eigenvalues().maxCoeff()));
}

namespace {

estimation::DragBallisticModel dragModel(const CrossingModel& m) {
  estimation::DragBallisticModel d;
  const double g = m.gravity_w.norm();
  d.g = g;
  d.up = g > 0.0 ? Eigen::Vector3d(-m.gravity_w / g) : Eigen::Vector3d::UnitZ();
  d.k = m.drag_k;
  d.q = m.accel_psd;
  d.substeps = 2;
  return d;
}

struct MeanCrossing {
  double tau;
  Vector6 x;  // state at the crossing
};

std::optional<MeanCrossing> meanCrossing(const Vector6& x0, const CrossingPlane& pl, const CrossingModel& m) {
  const Eigen::Vector3d& n = pl.normal;
  const double h0 = n.dot(x0.head<3>() - pl.point);
  if (!(h0 > 0.0)) return std::nullopt;  // already at or behind the plane
  if (m.kind == FlightModel::Ballistic || m.drag_k == 0.0) {
    // h(τ) = h0 + b τ + a τ², a = ½ n·g, b = n·v0: smallest positive root.
    const double a = 0.5 * n.dot(m.gravity_w), b = n.dot(x0.tail<3>());
    double tau = -1.0;
    if (std::abs(a) < 1e-15) {
      if (b < 0.0) tau = -h0 / b;
    } else {
      const double disc = b * b - 4.0 * a * h0;
      if (disc >= 0.0) {
        const double sq = std::sqrt(disc);
        // Numerically stable roots.
        const double qv = -0.5 * (b + (b >= 0.0 ? sq : -sq));
        const double r1 = qv / a, r2 = h0 / qv;
        double best = -1.0;
        for (double r : {r1, r2})
          if (std::isfinite(r) && r > 0.0 && (best < 0.0 || r < best)) best = r;
        tau = best;
      }
    }
    if (!(tau > 0.0) || tau > m.max_horizon) return std::nullopt;
    Vector6 x;
    x.head<3>() = x0.head<3>() + x0.tail<3>() * tau + 0.5 * m.gravity_w * tau * tau;
    x.tail<3>() = x0.tail<3>() + m.gravity_w * tau;
    if (!(n.dot(x.tail<3>()) < 0.0)) return std::nullopt;
    return MeanCrossing{tau, x};
  }
  const estimation::DragBallisticModel d = dragModel(m);
  Vector6 x = x0;
  double tau = 0.0;
  double h = h0;
  while (tau < m.max_horizon) {
    const double dt = std::min(m.step, m.max_horizon - tau);
    const Vector6 xn = d.propagateFixed(x, dt);
    const double hn = n.dot(xn.head<3>() - pl.point);
    if (hn <= 0.0) {
      // Newton from the bracketing state x (at tau, h > 0).
      double s = dt * h / (h - hn);  // secant start
      for (int it = 0; it < 20; ++it) {
        const Vector6 xs = s > 0.0 ? d.propagateFixed(x, s) : x;
        const double hs = n.dot(xs.head<3>() - pl.point);
        const double vs = n.dot(xs.tail<3>());
        if (!(vs < 0.0)) break;
        const double ds = -hs / vs;
        s = std::clamp(s + ds, 0.0, dt);
        if (std::abs(ds) < 1e-12) break;
      }
      const Vector6 xc = s > 0.0 ? d.propagateFixed(x, s) : x;
      if (!(n.dot(xc.tail<3>()) < 0.0)) return std::nullopt;
      return MeanCrossing{tau + s, xc};
    }
    x = xn;
    h = hn;
    tau += dt;
  }
  return std::nullopt;
}

void checkInput(const CrossingPlane& pl) {
  if (!pl.point.allFinite() || !pl.normal.allFinite() || std::abs(pl.normal.norm() - 1.0) > 1e-9)
    throw InvalidInput("predictCrossing: plane normal must be a finite unit vector");
}

}  // namespace

std::optional<Crossing> predictCrossing(const Vector6& x0, core::Timestamp t0, const CrossingPlane& plane,
                                        const CrossingModel& model) {
  checkInput(plane);
  if (!x0.allFinite()) throw InvalidInput("predictCrossing: non-finite state");
  const auto mc = meanCrossing(x0, plane, model);
  if (!mc) return std::nullopt;
  Crossing c;
  c.t = t0 + mc->tau;
  c.p = mc->x.head<3>();
  c.v = mc->x.tail<3>();
  // Put the point exactly on the plane (Newton leaves ~1e-12 m).
  c.p -= plane.normal * plane.normal.dot(c.p - plane.point);
  return c;
}

std::optional<Crossing> predictCrossing(const estimation::StateEstimate& est, const CrossingPlane& plane,
                                        const CrossingModel& model) {
  if (est.dim() != 6) throw InvalidInput("predictCrossing: expected a 6-state (p, v) estimate");
  const Vector6 x0 = est.x();
  auto c = predictCrossing(x0, est.t(), plane, model);
  if (!c) return c;
  const double tau = c->t - est.t();
  Matrix6 F;
  Matrix6 Q = Matrix6::Zero();
  if (model.kind == FlightModel::Ballistic || model.drag_k == 0.0) {
    F.setIdentity();
    F.topRightCorner<3, 3>() = tau * Eigen::Matrix3d::Identity();
    const double q = model.accel_psd;
    Q.topLeftCorner<3, 3>() = q * tau * tau * tau / 3.0 * Eigen::Matrix3d::Identity();
    Q.topRightCorner<3, 3>() = q * tau * tau / 2.0 * Eigen::Matrix3d::Identity();
    Q.bottomLeftCorner<3, 3>() = Q.topRightCorner<3, 3>();
    Q.bottomRightCorner<3, 3>() = q * tau * Eigen::Matrix3d::Identity();
  } else {
    estimation::DragBallisticModel d = dragModel(model);
    d.substeps = std::max(2, static_cast<int>(std::ceil(tau / 0.02)));
    F = d.jacobianFixed(x0, tau);
    if (model.accel_psd > 0.0) Q = d.processNoiseFixed(x0, tau);  // no heap: the bits of processNoise()
  }
  // est.P() without its temporary: the same product, evaluated into a per-thread buffer.
  thread_local Eigen::MatrixXd P_buffer(6, 6);
  P_buffer.noalias() = est.sqrtP() * est.sqrtP().transpose();
  const Matrix6 P = P_buffer;
  const Matrix6 Pt = F * P * F.transpose() + Q;
  const Eigen::Matrix3d Ppp = 0.5 * (Pt.topLeftCorner<3, 3>() + Pt.topLeftCorner<3, 3>().transpose());
  const Eigen::Vector3d& n = plane.normal;
  const double nv = n.dot(c->v);
  const Eigen::Matrix3d A = Eigen::Matrix3d::Identity() - c->v * n.transpose() / nv;
  c->cov_p = A * Ppp * A.transpose();
  c->var_t = n.dot(Ppp * n) / (nv * nv);
  return c;
}

}  // namespace viewline::planning
