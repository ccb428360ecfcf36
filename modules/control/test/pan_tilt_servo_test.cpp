#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <iostream>
#include <memory>

#include "viewline/control/pan_tilt_servo.h"
#include "viewline/core/error.h"
#include "viewline/core/frames.h"
#include "viewline/core/random.h"
#include "viewline/robots/simulated_pan_tilt.h"

using namespace viewline;
using control::PredictiveConfig;

TEST(VispPointServo, DrivesTheFeatureTowardsTheCentre) {
  control::PointServoConfig cfg;
  cfg.gain = 2.0;
  control::VispPointServo servo(cfg);
  robots::PanTiltKinematics k;
  const Eigen::Vector2d q(0.2, -0.1);
  // Target to the right of and below the centre: pan right (negative), tilt down (negative).
  const Eigen::Vector2d qd = servo.command(Eigen::Vector2d(0.1, 0.05), k.cVe(), k.eJe(q));
  EXPECT_LT(qd(0), 0.0);
  EXPECT_LT(qd(1), 0.0);
  // J q̇ = −λ e with J = L(s*) cVe eJe: check through the pseudo-inverse (J is invertible here).
  const Eigen::Matrix2d J = servo.jacobianPinv().inverse();
  EXPECT_NEAR((J * qd - (-2.0) * Eigen::Vector2d(0.1, 0.05)).norm(), 0.0, 1e-9);
  control::PointServoConfig bad;
  bad.interaction = "sometimes";
  EXPECT_THROW(control::VispPointServo{bad}, core::InvalidInput);
}

namespace {
// Kinematic closed loop without images: the target on a plane 1.3 m in front, seen through the
// exact projection with noise on the plane coordinates. Returns the RMS image error (rad).
struct LoopResult {
  double rms = 0.0;
  std::size_t rate_violations = 0, limit_hits = 0;
  int unsafe = 0;
  double reacquired_at = -1.0;
};

LoopResult runLoop(control::PanTiltController& ctrl, const robots::PanTiltLimits& limits,
                   const std::function<Eigen::Vector2d(double)>& path, double duration,
                   double occl_start = -1.0, double occl_len = 0.0) {
  robots::SimulatedPanTiltParams up;
  up.limits = limits;
  up.latency = 0.03;
  const Eigen::Isometry3d f_M_plane = [] {
    Eigen::Isometry3d m = Eigen::Isometry3d::Identity();
    m.linear() << 0, 0, 1, -1, 0, 0, 0, -1, 0;  // plane x = −y_f, plane y = −z_f, normal +x_f
    m.translation() = Eigen::Vector3d(1.3, 0.0, -0.25);
    return m;
  }();
  robots::PanTiltKinematics kin;
  up.q0 = kin.pointAt(f_M_plane * Eigen::Vector3d(path(0).x(), path(0).y(), 0))
              .cwiseMax(limits.q_min + Eigen::Vector2d::Constant(0.02))
              .cwiseMin(limits.q_max - Eigen::Vector2d::Constant(0.02));
  robots::SimulatedPanTiltUnit unit(up);
  core::Rng rng = core::makeRng(5);
  const double period = 1.0 / 30.0, sigma = 0.01;
  LoopResult r;
  double sum = 0.0;
  int n = 0;
  std::vector<robots::IssuedCommand> recent;
  for (int k = 0; k * period < duration; ++k) {
    const double t = k * period;
    const robots::JointState js = unit.read(t);
    const Eigen::Vector2d p = path(t);
    const Eigen::Vector3d s = kin.project(js.q, f_M_plane * Eigen::Vector3d(p.x(), p.y(), 0));
    const bool visible = std::abs(s.x()) < 0.34 && std::abs(s.y()) < 0.26 && !(t >= occl_start && t < occl_start + occl_len);
    control::TargetObservation obs;
    obs.stamp = t;
    obs.detected = visible;
    if (visible) {
      obs.plane = p + Eigen::Vector2d(core::gaussian(rng, sigma), core::gaussian(rng, sigma));
      obs.plane_cov = sigma * sigma * Eigen::Matrix2d::Identity();
      const Eigen::Vector3d sn = kin.project(js.q, f_M_plane * Eigen::Vector3d(obs.plane.x(), obs.plane.y(), 0));
      obs.feature = sn.head<2>();
      if (occl_start >= 0 && t >= occl_start + occl_len && r.reacquired_at < 0) r.reacquired_at = t;
    }
    ctrl.observe(obs);
    const double t_cmd = t + 0.01;
    control::ControlInput in;
    in.t = t_cmd;
    in.joints = unit.read(t_cmd);
    in.recent = recent;
    in.period = period;
    const control::ControlOutput out = ctrl.command(in);
    const auto e = robots::predictJointState(limits, in.joints, recent, up.latency, t_cmd + up.latency);
    if (!robots::isSafeCommand(limits, e.q, e.qdot, out.qdot, period, 1e-9)) ++r.unsafe;
    unit.commandVelocity(t_cmd, out.qdot);
    recent.push_back({t_cmd, out.qdot});
    if (recent.size() > 6) recent.erase(recent.begin());
    if (t > 3.0) { sum += s.head<2>().squaredNorm(); ++n; }
  }
  r.rms = std::sqrt(sum / n);
  r.rate_violations = unit.rateViolations();
  r.limit_hits = unit.limitHits();
  return r;
}

Eigen::Isometry3d planePose() {
  Eigen::Isometry3d m = Eigen::Isometry3d::Identity();
  m.linear() << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  m.translation() = Eigen::Vector3d(1.3, 0.0, -0.25);
  return m;
}
}  // namespace

TEST(PanTiltControllers, PredictionBeatsTheBaselineOnACircle) {
  const auto circle = [](double t) { return Eigen::Vector2d(0.3 * std::cos(0.5 * t), 0.3 * std::sin(0.5 * t)); };
  const auto limits = robots::PanTiltLimits::flirPtuD46();
  control::PointServoConfig servo;
  servo.gain = 4.0;
  control::BaselinePanTiltController base(servo, limits, 0.03);
  PredictiveConfig pc;
  pc.servo = servo;
  pc.filter.q = 0.01;
  control::PredictivePanTiltController ours(pc, limits, 0.03, planePose());
  const LoopResult rb = runLoop(base, limits, circle, 20.0);
  const LoopResult ro = runLoop(ours, limits, circle, 20.0);
  EXPECT_LT(ro.rms, rb.rms / 3.0) << "ours " << ro.rms << " baseline " << rb.rms;
  std::cout << "kinematic loop, circle: ours " << ro.rms << " rad, baseline " << rb.rms << " rad\n";
  EXPECT_EQ(ro.unsafe + rb.unsafe, 0);
  EXPECT_EQ(ro.rate_violations + ro.limit_hits + rb.rate_violations + rb.limit_hits, 0u);
}

TEST(PanTiltControllers, NeverCommandsOutsideNarrowLimits) {
  // The target runs far outside a ±10° pan / ±5° tilt box: the law must saturate, not hit the stops.
  robots::PanTiltLimits limits = robots::PanTiltLimits::flirPtuD46();
  limits.q_min = Eigen::Vector2d(core::deg2rad(-10.0), core::deg2rad(-15.0));
  limits.q_max = Eigen::Vector2d(core::deg2rad(10.0), core::deg2rad(-5.0));
  const auto wide = [](double t) { return Eigen::Vector2d(0.8 * std::sin(0.8 * t), 0.3 * std::cos(0.8 * t)); };
  PredictiveConfig pc;
  pc.servo.gain = 5.0;
  control::PredictivePanTiltController ours(pc, limits, 0.03, planePose());
  control::BaselinePanTiltController base(pc.servo, limits, 0.03);
  for (control::PanTiltController* c : {static_cast<control::PanTiltController*>(&ours),
                                         static_cast<control::PanTiltController*>(&base)}) {
    const LoopResult r = runLoop(*c, limits, wide, 30.0);
    EXPECT_EQ(r.unsafe, 0) << c->name();
    EXPECT_EQ(r.rate_violations, 0u) << c->name();
    EXPECT_EQ(r.limit_hits, 0u) << c->name();
  }
}

TEST(PanTiltControllers, SearchesAndReacquiresAfterALongLoss) {
  // A 3 s occlusion (longer than coast_time): ours searches and reacquires; the filter restarts.
  const auto line = [](double t) { return Eigen::Vector2d(0.25 * std::sin(0.3 * t), 0.0); };
  const auto limits = robots::PanTiltLimits::flirPtuD46();
  PredictiveConfig pc;
  pc.servo.gain = 4.0;
  pc.coast_time = 0.5;
  control::PredictivePanTiltController ours(pc, limits, 0.03, planePose());
  const LoopResult r = runLoop(ours, limits, line, 20.0, 6.0, 3.0);
  EXPECT_GE(ours.reacquisitions(), 1u);
  EXPECT_GT(r.reacquired_at, 0.0);
  EXPECT_LT(r.reacquired_at, 9.0 + 3.0);  // seen again within 3 s of the end of the occlusion
  EXPECT_EQ(r.unsafe, 0);
}
