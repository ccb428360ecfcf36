#include "viewline/scenarios/table_ball/observer.h"

#include <chrono>
#include <cmath>
#include <limits>

#include "viewline/core/checks.h"
#include "viewline/core/error.h"
#include "viewline/core/frames.h"
#include "viewline/estimation/kalman_filter.h"
#include "viewline/vision/table_geometry.h"

namespace viewline::scenarios {

Eigen::Vector2d tiltFromTableRotation(const Eigen::Matrix3d& w_R_t) {
  // Rx(a) Ry(b) = [[cb, 0, sb], [sa sb, ca, -sa cb], [-ca sb, sa, ca cb]].
  return {std::atan2(w_R_t(2, 1), w_R_t(1, 1)), std::atan2(w_R_t(0, 2), w_R_t(0, 0))};
}

Eigen::Isometry3d borderAwareTablePose(const core::Camera& camera, const std::array<Eigen::Vector2d, 4>& corners,
                                       const Eigen::Isometry3d& c_M_t, double side, double border_height,
                                       int iterations) {
  if (!(border_height > 0.0)) return c_M_t;
  // Normalised image points (distortion removed); the re-solution minimises the reprojection
  // error in normalised coordinates by Gauss-Newton from the current pose (vision::
  // refinePoseOnPoints: an analytic 6x6 step, no cv::solvePnP set-up per call, the same cost as
  // cv::solvePnP(SOLVEPNP_ITERATIVE, K = I) from that guess).
  std::array<Eigen::Vector2d, 4> image;
  for (std::size_t k = 0; k < 4; ++k) image[k] = camera.pixelToNormalized(corners[k]);
  Eigen::Isometry3d pose = c_M_t;
  const double h = 0.5 * side;
  for (int it = 0; it < iterations; ++it) {
    const Eigen::Vector3d cam_t = -(pose.linear().transpose() * pose.translation());  // t' = -Rᵀ t
    if (!(cam_t.z() > 2.0 * border_height)) break;                                     // too flat a view
    auto shift = [&](double coord) { return border_height * std::max(0.0, coord - h) / (cam_t.z() - border_height); };
    const double dxp = shift(cam_t.x()), dxm = shift(-cam_t.x()), dyp = shift(cam_t.y()), dym = shift(-cam_t.y());
    // P0 = (-,-), P1 = (+,-), P2 = (+,+), P3 = (-,+).
    const std::array<Eigen::Vector3d, 4> object = {Eigen::Vector3d(-h + dxm, -h + dym, 0.0), Eigen::Vector3d(h - dxp, -h + dym, 0.0),
                                                   Eigen::Vector3d(h - dxp, h - dyp, 0.0), Eigen::Vector3d(-h + dxm, h - dyp, 0.0)};
    const Eigen::Isometry3d next = vision::refinePoseOnPoints(pose, object, image, 1.0, 1.0, 0.0, 0.0);
    if (!next.matrix().allFinite() || next.translation().z() <= 0.0) break;
    pose = next;
  }
  return pose;
}

std::optional<Eigen::Vector3d> ballOnTablePlane(const core::Camera& camera, const vision::Circle& circle,
                                                const Eigen::Isometry3d& c_M_t, double ball_radius) {
  const vision::BallOnTableGeometry cone = vision::ballViewingCone(camera, circle);
  const Eigen::Matrix3d R = c_M_t.linear();
  const Eigen::Vector3d t_prime = -R.transpose() * c_M_t.translation();  // camera centre, table frame
  const Eigen::Vector3d v1 = R.transpose() * cone.ray_c;                   // cone axis, table frame
  if (!(std::abs(v1.z()) > 1e-6)) return std::nullopt;
  const double s = (ball_radius - t_prime.z()) / v1.z();  // (t' + s v1)_z = r
  if (!(s > 0.0) || !std::isfinite(s)) return std::nullopt;
  return Eigen::Vector3d(t_prime + s * v1);
}

TablePoseOffsetFilter::TablePoseOffsetFilter(double time_constant) : time_constant_(time_constant) {
  core::requirePositive(time_constant, "TablePoseOffsetFilter: time_constant");
}

bool TablePoseOffsetFilter::update(double t, const Eigen::Isometry3d& c_M_t_measured,
                                   const Eigen::Isometry3d& c_M_t_kinematic) {
  // Residual Δ = c_M_t_meas c_M_t_kin⁻¹: rotation vector and translation, both small (a fraction
  // of a degree and a few mm), so their average is the average of the poses to first order.
  const Eigen::Isometry3d d = c_M_t_measured * c_M_t_kinematic.inverse();
  const Eigen::AngleAxisd aa(d.linear());
  const Eigen::Vector3d omega = aa.angle() * aa.axis();
  if (!omega.allFinite() || !d.translation().allFinite()) return false;
  if (valid_ && ((omega - omega_).norm() > kGateRotation || (d.translation() - tau_).norm() > kGateTranslation)) {
    ++gated_;
    if (++gated_in_a_row_ < kRestartAfter) return false;
    valid_ = false;  // restart from this residual
  }
  gated_in_a_row_ = 0;
  if (!valid_) {
    omega_ = omega;
    tau_ = d.translation();
    valid_ = true;
  } else {
    // Exponential average over time τ: the steady Kalman gain of an offset that drifts slowly
    // (random walk) under white residual noise; dt-exact for dropped frames.
    const double a = -std::expm1(-std::max(t - t_, 0.0) / time_constant_);
    omega_ += a * (omega - omega_);
    tau_ += a * (d.translation() - tau_);
  }
  t_ = t;
  return true;
}

Eigen::Isometry3d TablePoseOffsetFilter::apply(const Eigen::Isometry3d& c_M_t_kinematic) const {
  Eigen::Isometry3d d = Eigen::Isometry3d::Identity();
  const double angle = omega_.norm();
  if (angle > 0.0) d.linear() = Eigen::AngleAxisd(angle, omega_ / angle).toRotationMatrix();
  d.translation() = tau_;
  return d * c_M_t_kinematic;
}

// -------------------------------------------------------------------------------------------

TableBallObserver::TableBallObserver(const core::Camera& camera, const TableBallObserverConfig& config)
    : camera_(camera), config_(config), detector_(camera, config.detector), tracker_(config.tracker),
      edges_(config.detector, config.edge_tracker) {
  core::requireFinite(config.gravity_w, "TableBallObserverConfig.gravity_w");
  if (config_.table_pose == TablePoseSource::AprilTag) {
    if (config_.tag_layout.empty()) throw core::InvalidInput("TableBallObserverConfig.tag_layout: empty for AprilTag table pose");
    tags_ = std::make_unique<vision::AprilTagTableDetector>(camera, config_.tag_layout, config_.tag_detector);
  }
  core::requireNonNegative(config_.table_pose_time_constant, "TableBallObserverConfig.table_pose_time_constant");
  if (config_.table_pose_time_constant > 0.0) pose_filter_.emplace(config_.table_pose_time_constant);
}

TableBallObserver::~TableBallObserver() = default;

void TableBallObserver::filterStep(double t, const std::optional<Eigen::Vector2d>& y) {
  tracker_.step(t, frame_.a_xy, y);
  frame_.estimate_valid = tracker_.initialized();
  if (frame_.estimate_valid) {
    frame_.x = tracker_.x();
    frame_.predictions = tracker_.predictions();
  }
}

const ObserverFrame& TableBallObserver::process(const cv::Mat& bgr, double t, const Eigen::Matrix3d& c_R_w,
                                                const Eigen::Isometry3d& c_M_t_nominal, double (*clock)(),
                                                ObserverStageTimes* times) {
  const auto t0 = std::chrono::steady_clock::now();
  // Stage timing for the latency bench: lap(slot) adds the time since the previous lap to slot.
  if (clock == nullptr) times = nullptr;
  if (times != nullptr) *times = {};
  double last_lap = times != nullptr ? clock() : 0.0;
  auto lap = [&](double ObserverStageTimes::*slot) {
    if (times == nullptr) return;
    const double now = clock();
    times->*slot += now - last_lap;
    last_lap = now;
  };
  const auto& model = config_.tracker.model;
  frame_.t = t;
  frame_.image = true;
  frame_.failure.clear();
  frame_.ball_circle.reset();
  frame_.measured.setConstant(std::numeric_limits<double>::quiet_NaN());

  std::optional<Eigen::Isometry3d> pose;
  std::optional<vision::Circle> circle;
  frame_.tracked = false;
  if (config_.edge_tracking && config_.table_pose == TablePoseSource::Corners && frame_.table_found &&
      frame_.ball_circle_prev) {
    const auto corners = edges_.trackCorners(bgr, frame_.corners);
    lap(&ObserverStageTimes::table);
    const auto ball = corners ? edges_.trackBall(bgr, *frame_.ball_circle_prev) : std::nullopt;
    lap(&ObserverStageTimes::ball);
    if (corners && ball) {
      const Eigen::Isometry3d p = borderAwareTablePose(camera_, *corners, c_M_t_, model.table_side,
                                                       std::max(config_.border_height, 1e-9), 1);
      lap(&ObserverStageTimes::pose);
      if (core::rotationAngle(p.linear(), c_M_t_.linear()) < 0.2) {
        pose = p;
        circle = ball;
        frame_.corners = *corners;
        frame_.tracked = true;
      }
    }
  }
  if (!frame_.tracked) {
    detector_.setPrior(c_M_t_nominal);  // quarter turns from the arm's kinematics
    const vision::TableScene scene = detector_.detect(bgr, t);
    lap(&ObserverStageTimes::table);
    circle = scene.ball_circle;
    if (config_.table_pose == TablePoseSource::Corners) {
      if (scene.table) {
        frame_.corners = scene.table->corners;
        pose = borderAwareTablePose(camera_, frame_.corners, scene.table->c_M_t, model.table_side, config_.border_height);
        lap(&ObserverStageTimes::pose);
      } else {
        frame_.failure = std::string("table: ") + vision::toString(scene.table.failure().reason) + " " +
                         scene.table.failure().message;
      }
    } else {
      const auto tag_table = tags_->detect(bgr, t);
      lap(&ObserverStageTimes::table);
      if (tag_table) {
        pose = tag_table->c_M_t;
        frame_.corners = tag_table->corners;
      } else {
        frame_.failure = std::string("tags: ") + vision::toString(tag_table.failure().reason) + " " +
                         tag_table.failure().message;
      }
    }
  }
  frame_.table_found = pose.has_value();
  if (pose) {
    c_M_t_ = *pose;
    have_table_ = true;
  }
  // The pose the ball and the tilt use: this frame's PnP pose, or the filtered one (step 2b).
  if (pose_filter_ && pose) pose_filter_->update(t, *pose, c_M_t_nominal);
  const bool filtered = pose_filter_ && pose_filter_->valid();
  const Eigen::Isometry3d c_M_t_used = filtered ? pose_filter_->apply(c_M_t_nominal) : c_M_t_;
  frame_.c_M_t = c_M_t_used;
  if (have_table_) {
    const Eigen::Matrix3d t_R_w = estimation::tableRotationInWorld(c_M_t_used.linear(), c_R_w);
    frame_.a_xy = estimation::rollingBallAcceleration(t_R_w, config_.gravity_w);
    frame_.measured_tilt = tiltFromTableRotation(t_R_w.transpose());
  }

  std::optional<Eigen::Vector2d> y, y_raw;
  frame_.ball_circle = circle;
  if (have_table_ && circle) {
    y_raw = ballOnTable(*circle, c_M_t_);
    y = filtered ? ballOnTable(*circle, c_M_t_used) : y_raw;
  } else if (!circle && frame_.failure.empty()) {
    frame_.failure = "ball: not found";
  }
  frame_.ball_found = y.has_value();
  frame_.ball_circle_prev = y ? circle : std::nullopt;
  frame_.measured_own_pose.setConstant(std::numeric_limits<double>::quiet_NaN());
  if (y) {
    frame_.measured = *y;
    // The raw measurement is scored where the filter had one (a frame whose own-pose ball fell
    // off the table keeps NaN: not measured).
    if (y_raw) frame_.measured_own_pose = *y_raw;
  }
  lap(&ObserverStageTimes::geometry);
  filterStep(t, y);
  lap(&ObserverStageTimes::filter);
  frame_.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return frame_;
}

std::optional<Eigen::Vector2d> TableBallObserver::ballOnTable(const vision::Circle& circle,
                                                              const Eigen::Isometry3d& c_M_t) const {
  const auto& model = config_.tracker.model;
  std::optional<Eigen::Vector2d> y;
  if (config_.ball_geometry == BallGeometry::KnownRadius) {
    y = vision::ballOnTableKnownRadius(camera_, circle, c_M_t, model.ball_radius).p_t.head<2>();
  } else if (config_.ball_geometry == BallGeometry::TablePlane) {
    if (const auto p = ballOnTablePlane(camera_, circle, c_M_t, model.ball_radius)) y = p->head<2>();
  } else if (const auto g = vision::ballOnTableUnknownRadius(camera_, circle, c_M_t)) {
    y = g->p_t.head<2>();
  }
  // A ball "found" far outside the table is a detection error, not a measurement.
  if (y && (!y->allFinite() || y->cwiseAbs().maxCoeff() > 0.5 * model.table_side + model.ball_radius)) y.reset();
  return y;
}

const ObserverFrame& TableBallObserver::predictOnly(double t) {
  const auto t0 = std::chrono::steady_clock::now();
  frame_.t = t;
  frame_.image = false;
  frame_.table_found = false;
  frame_.ball_found = false;
  frame_.failure = "no image";
  frame_.ball_circle.reset();
  frame_.ball_circle_prev.reset();
  frame_.measured.setConstant(std::numeric_limits<double>::quiet_NaN());
  frame_.measured_own_pose.setConstant(std::numeric_limits<double>::quiet_NaN());
  if (tracker_.initialized()) filterStep(t, std::nullopt);
  frame_.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return frame_;
}

}  // namespace viewline::scenarios
