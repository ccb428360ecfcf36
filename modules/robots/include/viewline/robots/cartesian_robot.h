#pragma once
// A robot that carries a tool (the catching box) and takes Cartesian set points: one interface
// for the simulated back ends below and for a real arm (an ABB IRB 140 with a streaming
// position interface such as EGM, or a Viper850 through vpRobotViper850, would implement the
// same three calls).
//
// Frames and units: world frame w (z up), SI units. The tool point is the centre of the hole in
// the box's front face; its orientation is fixed (the box front faces the thrower) and not part
// of the command. A command is a set point (position and velocity of the tool point) stamped
// with its issue time; a real controller streams one every control period and applies it after
// the command latency. The limits bound the tool point's speed and acceleration ([L]: 0.5 m/s
// and 13 m/s²), by default in Euclidean norm (|ṗ| <= v_max, |p̈| <= a_max: an arm's tool-point
// limit, the same in every direction) or, as an option, per Cartesian axis (a gantry whose axes
// have their own drives: a diagonal move then gets up to √3 times the limit). The planner
// (planning/motion_profile.h) produces set points that respect them; the simulated back end
// counts every set point that does not (tests assert none does) instead of silently fixing it.
//
// Two kinematic back ends, chosen in the scenario config:
//  - Stage: a Cartesian (gantry) stage; the workspace is an axis-aligned box.
//  - Arm:   the tool carried by a ViSP vpViper850 (its DH model and joint limits). Every set
//           point goes through the inverse kinematics (vpViper::getInverseKinematics, nearest
//           solution to the current joints) and must respect the joint limits; a set point
//           with no solution is refused (the arm holds its last valid set point, counted).

#include <Eigen/Geometry>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "viewline/core/time.h"

namespace viewline::robots {

/// How the tool point's speed and acceleration limits are measured.
enum class LimitNorm {
  Euclidean,  ///< |ṗ| <= v_max and |p̈| <= a_max (2-norm; an arm's tool-point limit)
  PerAxis     ///< |ṗ_i| <= v_max_i and |p̈_i| <= a_max_i on every world axis (a gantry)
};
/// Lower-case name of a limit norm ("euclidean", "per_axis").
const char* toString(LimitNorm n);

/// Cartesian limits of the tool point (Euclidean norm by default, per axis as an option).
struct CartesianLimits {
  Eigen::Vector3d v_max = Eigen::Vector3d::Constant(0.5);   ///< m/s: |ṗ| (Euclidean: all three equal) or |ṗ_i|
  Eigen::Vector3d a_max = Eigen::Vector3d::Constant(13.0);  ///< m/s²: |p̈| (Euclidean: all three equal) or |p̈_i|
  LimitNorm norm = LimitNorm::Euclidean;                     ///< how v_max and a_max are measured
  /// [L]'s ball catcher (ABB IRB 140): 0.5 m/s and 13 m/s² at the tool point (Euclidean norm).
  static CartesianLimits linderoth() { return {}; }
  /// Throws core::InvalidInput naming the field (positive and finite; equal components when Euclidean).
  void validate() const;
  /// True when velocity v (m/s) is within the limit, with relative tolerance `tol`.
  bool speedWithin(const Eigen::Vector3d& v, double tol = 0.0) const;
  /// True when acceleration a (m/s²) is within the limit, with relative tolerance `tol`.
  bool accelerationWithin(const Eigen::Vector3d& a, double tol = 0.0) const;
  /// The measure the limit applies to: |v| (Euclidean) or max_i |v_i| / v_max_i · v_max_0 (per axis), m/s.
  double speedOf(const Eigen::Vector3d& v) const;
  /// The same measure for an acceleration a, m/s².
  double accelerationOf(const Eigen::Vector3d& a) const;
};

/// Tool point position and velocity at time t.
struct CartesianState {
  core::Timestamp t = 0.0;  ///< time of the state, s
  Eigen::Vector3d p = Eigen::Vector3d::Zero();  ///< tool point position, world frame, m
  Eigen::Vector3d v = Eigen::Vector3d::Zero();  ///< tool point velocity, world frame, m/s
};

/// A robot carrying the catching box, commanded by streamed Cartesian set points of its tool point (world frame).
class CartesianRobot {
public:
  virtual ~CartesianRobot() = default;
  /// Short name for logs and summaries.
  virtual std::string name() const = 0;
  /// Cartesian limits of the tool point (the planner asks the robot, their owner).
  virtual const CartesianLimits& limits() const = 0;
  /// Delay between a set point's issue and its effect (s).
  virtual double commandLatency() const = 0;
  /// Can the tool point be at p (workspace; for the arm: an IK solution within the joint limits)?
  virtual bool reachable(const Eigen::Vector3d& p_w) const = 0;
  /// Streams one set point issued at t (non-decreasing times). Throws InvalidInput for NaN or
  /// a time before the previous set point.
  virtual void command(const CartesianState& setpoint) = 0;
  /// Tool state at time t (simulation: any t; hardware: now).
  virtual CartesianState read(core::Timestamp t) const = 0;
};

/// The vpViper850 holding the box: f = robot base frame, tool frame c = box frame (origin at
/// the hole centre, z along the box-front normal). w_M_f places the base in the world.
class ViperArmKinematics {
public:
  /// `tool_offset`: eMc translation (flange to hole centre, in the flange frame), m.
  /// `w_R_box`: fixed orientation of the box in the world.
  ViperArmKinematics(const Eigen::Isometry3d& w_M_f, const Eigen::Matrix3d& w_R_box,
                     const Eigen::Vector3d& tool_offset);
  ~ViperArmKinematics();
  /// Copies the model (deep copy of the ViSP robot).
  ViperArmKinematics(const ViperArmKinematics&);
  /// Assigns the model (deep copy of the ViSP robot).
  ViperArmKinematics& operator=(const ViperArmKinematics&);

  /// Joint solution (6) for the box at p_w, nearest to `q_seed`, within the joint limits
  /// (checked again here, with `margin` rad), or nothing.
  std::optional<Eigen::Matrix<double, 6, 1>> inverse(const Eigen::Vector3d& p_w,
                                                     const Eigen::Matrix<double, 6, 1>& q_seed,
                                                     double margin = 0.0) const;
  /// Box pose in the world for joints q (forward kinematics, vpViper::get_fMc).
  Eigen::Isometry3d forward(const Eigen::Matrix<double, 6, 1>& q) const;
  /// Lower joint limits (6 joints, rad).
  Eigen::Matrix<double, 6, 1> jointMin() const;
  /// Upper joint limits (6 joints, rad).
  Eigen::Matrix<double, 6, 1> jointMax() const;
  /// Fixed orientation of the box in the world (w_R_box).
  const Eigen::Matrix3d& boxRotation() const { return w_R_box_; }

private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  Eigen::Isometry3d w_M_f_;
  Eigen::Matrix3d w_R_box_;
};

/// Kinematics of the simulated Cartesian robot: a gantry stage or the vpViper850 arm.
enum class CartesianBackEnd { Stage, Arm };
/// Lower-case name of a back end ("stage", "arm").
const char* toString(CartesianBackEnd k);

/// Configuration of the simulated Cartesian robot (limits, latency, workspace; arm mounting).
struct SimulatedCartesianConfig {
  CartesianBackEnd kind = CartesianBackEnd::Stage;  ///< stage or arm
  CartesianLimits limits;  ///< velocity and acceleration limits of the tool point (Euclidean or per axis)
  double latency = 0.008;          ///< s between a set point's issue and its effect
  Eigen::Vector3d home = Eigen::Vector3d(0.0, 0.0, 1.2);      ///< tool point at rest, world
  Eigen::Vector3d workspace_min = Eigen::Vector3d(-0.1, -0.6, 0.7);  ///< stage box (and arm bounds)
  /// Upper corner of the stage box (and arm bounds), world, m
  Eigen::Vector3d workspace_max = Eigen::Vector3d(0.1, 0.6, 1.7);
  // Arm only.
  Eigen::Isometry3d w_M_base = Eigen::Isometry3d::Identity();  ///< arm only: pose of the robot base in the world
  Eigen::Matrix3d w_R_box = Eigen::Matrix3d::Identity();  ///< arm only: fixed box orientation in the world
  /// Arm only: flange to hole centre, in the flange frame, m
  Eigen::Vector3d tool_offset = Eigen::Vector3d(0.0, 0.0, 0.2);
  double joint_margin = 0.02;      ///< rad kept from each joint limit
  /// Tolerance of the limit check of the streamed set points (relative).
  double limit_tolerance = 1e-6;
  /// Throws core::InvalidInput naming the field.
  void validate() const;
};

/// Simulated back end: the tool follows the streamed set points exactly, `latency` later
/// (piecewise cubic Hermite between set points: position and velocity continuous). Set points
/// are checked against the limits (velocity directly; acceleration as the velocity difference
/// between consecutive set points over their interval) and the workspace / IK.
class SimulatedCartesianRobot : public CartesianRobot {
public:
  /// Builds the robot (validates the config, throws core::InvalidInput); the tool rests at home at t = 0.
  explicit SimulatedCartesianRobot(SimulatedCartesianConfig cfg);
  /// "simulated Cartesian stage" or "simulated vpViper850 arm".
  std::string name() const override;
  /// The configured limits.
  const CartesianLimits& limits() const override { return cfg_.limits; }
  double commandLatency() const override { return cfg_.latency; }
  bool reachable(const Eigen::Vector3d& p_w) const override;
  void command(const CartesianState& setpoint) override;
  CartesianState read(core::Timestamp t) const override;

  /// Forget the history; the tool is at `home` at rest (as if a set point (home, 0) was issued at t).
  void reset(core::Timestamp t);
  /// The configuration in use.
  const SimulatedCartesianConfig& config() const { return cfg_; }
  /// Number of set points received.
  std::size_t setpoints() const { return setpoints_; }
  /// Set points whose velocity exceeded the limits (tests assert 0).
  std::size_t velocityViolations() const { return v_violations_; }
  /// Set points whose implied acceleration exceeded the limits (tests assert 0).
  std::size_t accelerationViolations() const { return a_violations_; }
  /// Set points refused (no IK solution within the joint limits, or outside the workspace).
  std::size_t refusedSetpoints() const { return refused_; }
  double maxSpeedSeen() const { return max_v_; }       ///< max speed over set points, m/s (limits().speedOf)
  double maxAccelerationSeen() const { return max_a_; } ///< max |Δv / Δt| over set points, m/s² (limits().accelerationOf)
  /// Last joint solution (arm back end), zeros for the stage.
  const Eigen::Matrix<double, 6, 1>& joints() const { return q_; }
  /// The arm's kinematics (nullptr for the stage).
  const ViperArmKinematics* arm() const { return arm_ ? &*arm_ : nullptr; }

private:
  SimulatedCartesianConfig cfg_;
  std::optional<ViperArmKinematics> arm_;
  std::vector<CartesianState> hist_;  ///< accepted set points (effect time = t + latency)
  Eigen::Matrix<double, 6, 1> q_ = Eigen::Matrix<double, 6, 1>::Zero();
  std::size_t setpoints_ = 0, v_violations_ = 0, a_violations_ = 0, refused_ = 0;
  double max_v_ = 0.0, max_a_ = 0.0;
};

}  // namespace viewline::robots
