#pragma once
// Pan-tilt visual servoing ([T], SPEC §5): keep a moving target at the image centre.
//
// Baseline (ViSP's own PTU-46 / Biclops examples): a point feature s = (x, y)
// (normalised image coordinates of the target, depth fixed at Z = 1), desired
// s* = (0, 0), task EYEINHAND_L_cVe_eJe:
//
//     q̇ = −λ (L cVe eJe)⁺ (s − s*)                                      (1)
//
// with L the 2x6 interaction matrix of the point (at s* for "desired", at s for
// "current"), cVe and eJe from the unit's kinematic model (vpPtu46). No
// prediction: the law reacts to where the target *was* when the image was taken.
//
// Ours: the same law plus feed-forward of the target motion predicted by a
// Kalman filter, with the latency compensated. The filter (tracking::PlanarTargetFilter)
// estimates the target on its (known) plane, in plane coordinates (m), with a
// constant-velocity, constant-acceleration (Wiener) or Singer model (or CT, IMM, ...). At the issue time t of a
// command that acts from t_e = t + latency (+ lead), it predicts the target
// position P̂ and velocity V̂ at t_e, and the joints q_e at t_e (the drive model
// with the commands still in flight, robots::predictJointState). With the
// target in the camera at q_e, P_c = c_M_f(q_e) P̂ = (X, Y, Z), ŝ = (X/Z, Y/Z),
// and V_c = c_R_f(q_e) V̂, the feature motion that the target alone causes is
//
//     ṡ_T = ((V_cx − x V_cz) / Z, (V_cy − y V_cz) / Z),
//
// and the command is
//
//     q̇ = −λ J⁺ (ŝ − s*) − J⁺ ṡ_T,    J = L cVe eJe(q_e)                (2)
//
// so that ṡ = J q̇ + ṡ_T = −λ (ŝ − s*): the error decays at rate λ instead of
// settling at the lag ṡ_T / λ of law (1). J⁺ is vpServo's own pseudo-inverse.
// λ of (2) is PredictiveConfig::gain when set (the baseline keeps servo.gain): law
// (2) acts on the predicted error at the effect time, so a higher λ follows the
// filter's corrections faster without the delay that limits law (1)'s gain.
//
// Both laws' outputs go through robots::limitVelocityCommand (rate limit, and
// joint limits with braking from the predicted state at the effect time), so no
// command outside the limits is ever issued.
//
// Target lost (ours): for `coast_time` after the last accepted measurement the
// law keeps following the prediction (an occlusion shorter than that is
// bridged); after it, a search: an Archimedean spiral in joint space around the
// joints that pointed at the last prediction, growing at `search_growth` rad per
// turn up to `search_radius`, at `search_speed` rad/s along the path. The first
// detection after a loss re-initialises the filter at the measurement
// (reacquisition). While tracking, a measurement whose NIS exceeds the
// chi-square gate is rejected; `reinit_after` consecutive rejections also
// re-initialise the filter. The baseline stops (zero velocity) when the target is
// not detected, as the ViSP examples do.

#include <Eigen/Geometry>
#include <memory>
#include <string>
#include <vector>
#include <visp3/core/vpMatrix.h>
#include <visp3/core/vpVelocityTwistMatrix.h>

#include "viewline/core/time.h"
#include "viewline/robots/pan_tilt_kinematics.h"
#include "viewline/robots/pan_tilt_unit.h"
#include "viewline/tracking/planar_target/filter.h"

namespace viewline::control {

// ---------------------------------------------------------------------------------------------
// The ViSP law (1).

/// Configuration of ViSP's point-feature servo law (1).
struct PointServoConfig {
  double gain = 0.2;                     ///< λ (1/s)
  std::string interaction = "desired";   ///< "desired" (L at s*), "current" (L at s) or "mean"
  void validate() const;                 ///< throws core::InvalidInput naming the field
};

/// ViSP's point servo (vpServo, EYEINHAND_L_cVe_eJe) on a pan-tilt unit: law (1), no prediction.
class VispPointServo {
public:
  /// Builds the vpServo task (throws core::InvalidInput for a bad config).
  explicit VispPointServo(const PointServoConfig& config = {});
  ~VispPointServo();
  VispPointServo(const VispPointServo&) = delete;
  VispPointServo& operator=(const VispPointServo&) = delete;

  /// q̇ = −λ (L cVe eJe)⁺ (s − s*) for the normalised point s (depth 1), s* = (0, 0).
  Eigen::Vector2d command(const Eigen::Vector2d& s, const vpVelocityTwistMatrix& cVe, const vpMatrix& eJe);
  /// (L cVe eJe)⁺ (2 x 2) of the last command().
  Eigen::Matrix2d jacobianPinv() const;
  /// The configuration in use.
  const PointServoConfig& config() const { return config_; }

private:
  struct Impl;
  PointServoConfig config_;
  std::unique_ptr<Impl> impl_;
};

// ---------------------------------------------------------------------------------------------
// The target filter is tracking::PlanarTargetFilter (viewline/tracking/planar_target/filter.h).

// ---------------------------------------------------------------------------------------------
// Controllers (one interface for the scenario loop).

/// What the camera saw in one image, time-stamped with the capture time.
struct TargetObservation {
  core::Timestamp stamp = 0.0;  ///< capture time of the image, s
  bool detected = false;  ///< true when the target was found in the image (other fields are meaningless otherwise)
  Eigen::Vector2d feature = Eigen::Vector2d::Zero();    ///< normalised (x, y) in the capture camera
  Eigen::Vector2d plane = Eigen::Vector2d::Zero();      ///< measured position on the target plane (m)
  Eigen::Matrix2d plane_cov = Eigen::Matrix2d::Identity();  ///< its covariance (m²)
};

/// What a pan-tilt controller gets at each control period: time, measured joints and commands in flight.
struct ControlInput {
  core::Timestamp t = 0.0;              ///< issue time of the command
  robots::JointState joints;            ///< measured joint state at t
  std::vector<robots::IssuedCommand> recent;  ///< commands issued in the last latency + period
  double period = 1.0 / 30.0;           ///< s until the next command (the hold time)
};

/// What the controller is doing: following measurements, following the prediction only, searching, or nothing yet.
enum class TrackingMode { Tracking, Coasting, Searching, Idle };
/// Lower-case name of a mode ("tracking", "coasting", "searching", "idle").
const char* toString(TrackingMode mode);

/// A pan-tilt controller's output for one period: the joint velocity command (rad/s) and what it aimed at.
struct ControlOutput {
  Eigen::Vector2d qdot = Eigen::Vector2d::Zero();            ///< the command (limited)
  Eigen::Vector2d qdot_unlimited = Eigen::Vector2d::Zero();  ///< before the limiter
  TrackingMode mode = TrackingMode::Idle;  ///< what the controller was doing
  bool has_prediction = false;  ///< true when predicted_feature and predicted_plane are set
  Eigen::Vector2d predicted_feature = Eigen::Vector2d::Zero();  ///< ŝ at the effect time (normalised)
  Eigen::Vector2d predicted_plane = Eigen::Vector2d::Zero();    ///< P̂ on the plane at the effect time
};

/// Joint-limit handling of the velocity limiter.
struct LimitConfig {
  double margin = 0.0087;   ///< rad kept from the joint limits (0.5°)
};

/// Interface of a pan-tilt controller in the scenario loop: observations in, joint velocity commands out.
class PanTiltController {
public:
  virtual ~PanTiltController() = default;
  /// Short name for summaries and logs ("visp_baseline", "predictive").
  virtual std::string name() const = 0;
  /// Takes the observation of one image (time-stamped with its capture time).
  virtual void observe(const TargetObservation& observation) = 0;
  /// Joint velocity command (rad/s, pan and tilt) for the period starting at input.t, within the unit's limits.
  virtual ControlOutput command(const ControlInput& input) = 0;
};

/// Law (1) on the raw measured feature; zero velocity when the target is not detected.
class BaselinePanTiltController : public PanTiltController {
public:
  /// `kinematics`: the unit's model as the controller knows it (camera mount from the hand-eye
  /// calibration; vpPtu46's nominal mount by default).
  BaselinePanTiltController(const PointServoConfig& servo, const robots::PanTiltLimits& limits, double latency,
                            const LimitConfig& limit_config = {},
                            const robots::PanTiltKinematics& kinematics = robots::PanTiltKinematics());
  std::string name() const override { return "visp_baseline"; }
  void observe(const TargetObservation& observation) override { last_ = observation; }
  ControlOutput command(const ControlInput& input) override;

private:
  robots::PanTiltKinematics kinematics_;
  VispPointServo servo_;
  robots::PanTiltLimits limits_;
  double latency_;
  LimitConfig limit_config_;
  TargetObservation last_;
};

/// Configuration of the predictive law (2): servo, target filter, gain, lead, coasting and search.
struct PredictiveConfig {
  PointServoConfig servo;  ///< point servo of the law (interaction matrix; its gain when gain = 0)
  tracking::TargetFilterConfig filter;  ///< target filter on the plane (motion model, noise, gate)
  double gain = 0.0;              ///< λ (1/s) of law (2); 0: servo.gain (the baseline's)
  double lead = 0.0;              ///< s predicted beyond the command latency (e.g. half a period)
  bool feed_forward = true;       ///< the −J⁺ ṡ_T term of (2)
  double coast_time = 1.5;        ///< s of following the prediction without measurements
  double search_speed = 0.6;      ///< rad/s along the search spiral
  double search_growth = 0.12;    ///< rad of radius per turn
  double search_radius = 0.8;     ///< rad, largest spiral radius (then it restarts)
  double search_gain = 4.0;       ///< 1/s, pull towards the spiral point
  LimitConfig limits;  ///< joint-limit margin of the limiter
  /// Throws core::InvalidInput naming the field.
  void validate() const;
};

/// Law (2): prediction, feed-forward, latency compensation, search and reacquisition.
class PredictivePanTiltController : public PanTiltController {
public:
  /// f_M_plane: pose of the target plane (x, y in the plane) in the unit's base frame;
  /// `kinematics`: the unit's model as the controller knows it (see BaselinePanTiltController).
  PredictivePanTiltController(const PredictiveConfig& config, const robots::PanTiltLimits& limits, double latency,
                              const Eigen::Isometry3d& f_M_plane,
                              const robots::PanTiltKinematics& kinematics = robots::PanTiltKinematics());
  std::string name() const override { return "predictive"; }
  void observe(const TargetObservation& observation) override;
  ControlOutput command(const ControlInput& input) override;

  /// The target filter (on the target plane, plane coordinates in m).
  const tracking::PlanarTargetFilter& filter() const { return filter_; }
  /// The filter's x(k|k) position after the last fused measurement (valid when lastUpdate().accepted).
  const Eigen::Vector2d& filteredPlane() const { return filtered_; }
  /// Report of the filter's last measurement update (NIS, accepted or rejected).
  const tracking::PlanarTargetFilter::Update& lastUpdate() const { return last_update_; }
  /// Number of reacquisitions (filter re-initialised after a loss or repeated rejections).
  std::size_t reacquisitions() const { return reacquisitions_; }

private:
  PredictiveConfig config_;
  robots::PanTiltKinematics kinematics_;
  VispPointServo servo_;
  robots::PanTiltLimits limits_;
  double latency_;
  Eigen::Isometry3d f_M_plane_;
  tracking::PlanarTargetFilter filter_;
  Eigen::Vector2d filtered_ = Eigen::Vector2d::Zero();
  tracking::PlanarTargetFilter::Update last_update_;
  core::Timestamp last_accepted_ = -1e300;
  bool searching_ = false;
  core::Timestamp search_start_ = 0.0;
  Eigen::Vector2d search_center_ = Eigen::Vector2d::Zero();
  std::size_t reacquisitions_ = 0;
};

}  // namespace viewline::control
