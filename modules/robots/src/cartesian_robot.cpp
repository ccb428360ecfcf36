#include "viewline/robots/cartesian_robot.h"

#include <algorithm>
#include <cmath>
#include <visp3/core/vpColVector.h>
#include <visp3/core/vpHomogeneousMatrix.h>
#include <visp3/robot/vpViper850.h>

#include "viewline/core/checks.h"
#include "viewline/core/error.h"
#include "viewline/core/frames.h"

namespace viewline::robots {

using core::InvalidInput;
using Vector6 = Eigen::Matrix<double, 6, 1>;

const char* toString(LimitNorm n) { return n == LimitNorm::Euclidean ? "euclidean" : "per_axis"; }

void CartesianLimits::validate() const {
  for (int i = 0; i < 3; ++i) {
    if (!(std::isfinite(v_max(i)) && v_max(i) > 0.0))
      throw InvalidInput("CartesianLimits.v_max[" + std::to_string(i) + "]: expected a positive finite speed (m/s)");
    if (!(std::isfinite(a_max(i)) && a_max(i) > 0.0))
      throw InvalidInput("CartesianLimits.a_max[" + std::to_string(i) +
                         "]: expected a positive finite acceleration (m/s²)");
  }
  if (norm == LimitNorm::Euclidean && (v_max.maxCoeff() != v_max.minCoeff() || a_max.maxCoeff() != a_max.minCoeff()))
    throw InvalidInput("CartesianLimits: a Euclidean-norm limit is one number: expected equal v_max and a_max components");
}

double CartesianLimits::speedOf(const Eigen::Vector3d& v) const {
  if (norm == LimitNorm::Euclidean) return v.norm();
  return v.cwiseAbs().cwiseQuotient(v_max).maxCoeff() * v_max(0);
}

double CartesianLimits::accelerationOf(const Eigen::Vector3d& a) const {
  if (norm == LimitNorm::Euclidean) return a.norm();
  return a.cwiseAbs().cwiseQuotient(a_max).maxCoeff() * a_max(0);
}

bool CartesianLimits::speedWithin(const Eigen::Vector3d& v, double tol) const {
  return speedOf(v) <= v_max(0) * (1.0 + tol) + 1e-12;
}

bool CartesianLimits::accelerationWithin(const Eigen::Vector3d& a, double tol) const {
  return accelerationOf(a) <= a_max(0) * (1.0 + tol) + 1e-9;
}

const char* toString(CartesianBackEnd k) { return k == CartesianBackEnd::Stage ? "stage" : "arm"; }

// ------------------------------------------------------------------------------------------------

struct ViperArmKinematics::Impl {
  vpViper850 robot;
};

ViperArmKinematics::ViperArmKinematics(const Eigen::Isometry3d& w_M_f, const Eigen::Matrix3d& w_R_box,
                                       const Eigen::Vector3d& tool_offset)
    : impl_(std::make_unique<Impl>()), w_M_f_(w_M_f), w_R_box_(w_R_box) {
  core::requireFinite(tool_offset, "ViperArmKinematics: tool_offset");
  core::requireFinite(w_M_f.matrix(), "ViperArmKinematics: w_M_base");
  if ((w_R_box.transpose() * w_R_box - Eigen::Matrix3d::Identity()).norm() > 1e-6 || w_R_box.determinant() < 0.0)
    throw InvalidInput("ViperArmKinematics: w_R_box is not a rotation");
  vpHomogeneousMatrix eMc;
  eMc[0][3] = tool_offset.x();
  eMc[1][3] = tool_offset.y();
  eMc[2][3] = tool_offset.z();
  impl_->robot.init(vpViper850::TOOL_CUSTOM, eMc);
}

ViperArmKinematics::~ViperArmKinematics() = default;
ViperArmKinematics::ViperArmKinematics(const ViperArmKinematics& o)
    : impl_(std::make_unique<Impl>(*o.impl_)), w_M_f_(o.w_M_f_), w_R_box_(o.w_R_box_) {}
ViperArmKinematics& ViperArmKinematics::operator=(const ViperArmKinematics& o) {
  if (this != &o) {
    impl_ = std::make_unique<Impl>(*o.impl_);
    w_M_f_ = o.w_M_f_;
    w_R_box_ = o.w_R_box_;
  }
  return *this;
}

static vpColVector toVp(const Vector6& q) {
  vpColVector v(6);
  for (unsigned i = 0; i < 6; ++i) v[i] = q(static_cast<Eigen::Index>(i));
  return v;
}
static Vector6 fromVp(const vpColVector& v) {
  Vector6 q;
  for (unsigned i = 0; i < 6; ++i) q(static_cast<Eigen::Index>(i)) = v[i];
  return q;
}

std::optional<Vector6> ViperArmKinematics::inverse(const Eigen::Vector3d& p_w, const Vector6& q_seed,
                                                   double margin) const {
  if (!p_w.allFinite()) return std::nullopt;
  Eigen::Isometry3d w_M_c = Eigen::Isometry3d::Identity();
  w_M_c.linear() = w_R_box_;
  w_M_c.translation() = p_w;
  const vpHomogeneousMatrix fMc = core::toVisp(w_M_f_.inverse() * w_M_c);
  vpColVector q = toVp(q_seed);
  const unsigned n = impl_->robot.getInverseKinematics(fMc, q, false);
  if (n == 0) return std::nullopt;
  const Vector6 sol = fromVp(q);
  const Vector6 lo = jointMin(), hi = jointMax();
  for (int i = 0; i < 6; ++i)
    if (!(sol(i) >= lo(i) + margin && sol(i) <= hi(i) - margin)) return std::nullopt;
  // ViSP returns the nearest solution it found; make sure it really places the box there.
  const Eigen::Isometry3d check = forward(sol);
  if ((check.translation() - p_w).norm() > 1e-6 || (check.linear() - w_R_box_).norm() > 1e-6) return std::nullopt;
  return sol;
}

Eigen::Isometry3d ViperArmKinematics::forward(const Vector6& q) const {
  vpHomogeneousMatrix fMc;
  impl_->robot.get_fMc(toVp(q), fMc);
  return w_M_f_ * core::toEigen(fMc);
}

Vector6 ViperArmKinematics::jointMin() const { return fromVp(impl_->robot.getJointMin()); }
Vector6 ViperArmKinematics::jointMax() const { return fromVp(impl_->robot.getJointMax()); }

// ------------------------------------------------------------------------------------------------

void SimulatedCartesianConfig::validate() const {
  limits.validate();
  if (!(std::isfinite(latency) && latency >= 0.0)) throw InvalidInput("robot.latency_s: expected a finite value >= 0");
  core::requireFinite(home, "robot.home");
  core::requireFinite(workspace_min, "robot.workspace_min");
  core::requireFinite(workspace_max, "robot.workspace_max");
  for (int i = 0; i < 3; ++i)
    if (!(workspace_min(i) <= home(i) && home(i) <= workspace_max(i)))
      throw InvalidInput("robot.home: expected inside [workspace_min, workspace_max] on every axis");
  if (!(std::isfinite(joint_margin) && joint_margin >= 0.0))
    throw InvalidInput("robot.joint_margin_deg: expected a finite value >= 0");
}

SimulatedCartesianRobot::SimulatedCartesianRobot(SimulatedCartesianConfig cfg) : cfg_(std::move(cfg)) {
  cfg_.validate();
  if (cfg_.kind == CartesianBackEnd::Arm) {
    arm_.emplace(cfg_.w_M_base, cfg_.w_R_box, cfg_.tool_offset);
    // A seed posture for the home IK: try a few elbow/wrist configurations, keep the first that works.
    std::optional<Vector6> q;
    const double seeds[][6] = {{0, -1.0, 2.0, 0, 0.6, 0},  {0, -0.6, 1.6, 0, 0.6, 0},   {0, 0, 1.57, 0, 0, 0},
                               {0, -1.57, 3.0, 0, 1.0, 0}, {0, -0.3, 0.5, 0, -0.3, 0}, {0, 0, 0, 0, 0, 0}};
    for (const auto& sd : seeds) {
      Vector6 seed;
      for (int i = 0; i < 6; ++i) seed(i) = sd[i];
      q = arm_->inverse(cfg_.home, seed, cfg_.joint_margin);
      if (q) break;
    }
    if (!q)
      throw InvalidInput("robot.home: the vpViper850 has no inverse-kinematics solution within its joint limits "
                         "for the home box pose (check robot.arm.base_position, tool_offset)");
    q_ = *q;
  }
  reset(0.0);
}

std::string SimulatedCartesianRobot::name() const {
  return cfg_.kind == CartesianBackEnd::Stage ? "simulated Cartesian stage" : "simulated vpViper850 arm";
}

bool SimulatedCartesianRobot::reachable(const Eigen::Vector3d& p) const {
  if (!p.allFinite()) return false;
  for (int i = 0; i < 3; ++i)
    if (p(i) < cfg_.workspace_min(i) || p(i) > cfg_.workspace_max(i)) return false;
  if (arm_) return arm_->inverse(p, q_, cfg_.joint_margin).has_value();
  return true;
}

void SimulatedCartesianRobot::reset(core::Timestamp t) {
  hist_.clear();
  hist_.push_back({t, cfg_.home, Eigen::Vector3d::Zero()});
  if (arm_) {
    if (auto q = arm_->inverse(cfg_.home, q_, cfg_.joint_margin)) q_ = *q;
  }
}

void SimulatedCartesianRobot::command(const CartesianState& sp) {
  if (!std::isfinite(sp.t) || !sp.p.allFinite() || !sp.v.allFinite())
    throw InvalidInput("SimulatedCartesianRobot::command: non-finite set point");
  const CartesianState& last = hist_.back();
  if (sp.t < last.t) throw InvalidInput("SimulatedCartesianRobot::command: set point time goes backwards");
  ++setpoints_;
  const CartesianLimits& lim = cfg_.limits;
  max_v_ = std::max(max_v_, lim.speedOf(sp.v));
  if (!lim.speedWithin(sp.v, cfg_.limit_tolerance)) ++v_violations_;
  const double dt = sp.t - last.t;
  if (dt > 1e-9) {
    // The mean acceleration over the interval (|Δv| / Δt <= a_max when |p̈| <= a_max throughout).
    const Eigen::Vector3d a = (sp.v - last.v) / dt;
    max_a_ = std::max(max_a_, lim.accelerationOf(a));
    if (!lim.accelerationWithin(a, cfg_.limit_tolerance)) ++a_violations_;
  }
  if (!reachable(sp.p)) {
    ++refused_;
    hist_.push_back({sp.t, last.p, Eigen::Vector3d::Zero()});  // hold
    return;
  }
  if (arm_) {
    if (auto q = arm_->inverse(sp.p, q_, cfg_.joint_margin)) q_ = *q;
  }
  if (dt <= 1e-12) {
    hist_.back() = sp;
  } else {
    hist_.push_back(sp);
  }
  if (hist_.size() > 4096) hist_.erase(hist_.begin(), hist_.begin() + 2048);
}

CartesianState SimulatedCartesianRobot::read(core::Timestamp t) const {
  const double tc = t - cfg_.latency;  // the set point time that acts at t
  CartesianState out;
  out.t = t;
  if (tc <= hist_.front().t) {
    out.p = hist_.front().p;
    out.v = hist_.front().v;
    return out;
  }
  if (tc >= hist_.back().t) {
    out.p = hist_.back().p;  // hold the last set point (no extrapolation)
    out.v = hist_.back().v;
    return out;
  }
  auto it = std::upper_bound(hist_.begin(), hist_.end(), tc,
                             [](double x, const CartesianState& s) { return x < s.t; });
  const CartesianState& b = *it;
  const CartesianState& a = *(it - 1);
  const double h = b.t - a.t;
  const double s = (tc - a.t) / h;
  // Cubic Hermite between (p, v) set points.
  const double h00 = 2 * s * s * s - 3 * s * s + 1, h10 = s * s * s - 2 * s * s + s;
  const double h01 = -2 * s * s * s + 3 * s * s, h11 = s * s * s - s * s;
  out.p = h00 * a.p + h10 * h * a.v + h01 * b.p + h11 * h * b.v;
  const double d00 = (6 * s * s - 6 * s) / h, d10 = 3 * s * s - 4 * s + 1;
  const double d01 = (-6 * s * s + 6 * s) / h, d11 = 3 * s * s - 2 * s;
  out.v = d00 * a.p + d10 * a.v + d01 * b.p + d11 * b.v;
  return out;
}

}  // namespace viewline::robots
