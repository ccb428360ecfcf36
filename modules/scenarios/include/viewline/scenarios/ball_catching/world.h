#pragma once
// Ball catching: the simulated world of one throw and of the registration, and the cameras that
// watch it.
//
// World (the `catching` rig's frame, calib/rigs/catching/truth.yaml): z up, origin on the floor
// below the thrower, x towards the robot. The box hangs on the robot with its front face in the
// plane through the hole centre `robot.home` with unit normal `box.normal` (towards the thrower,
// default −x). A textured room (sim::makeRoom) is the static background.
//
// The throw (drawThrow): release point uniform in a box, aim point uniform in a disc of radius
// aim_radius around the hole's home position on the box-front plane, mean horizontal speed
// uniform in [speed_min, speed_max]; the flight time is the horizontal distance over that speed,
// and the launch velocity is solved (Newton on the 3 components, with the true drag) so that the
// ball centre is at the aim point at that time. Spin-free: p̈ = g − k |ṗ| ṗ,
// k = ρ Cd π r² / (2 m) (sim::DragFlight, RK4 at 1 ms).

#include <Eigen/Geometry>
#include <optional>
#include <vector>

#include "viewline/core/random.h"
#include "viewline/robots/cartesian_robot.h"
#include "viewline/runtime/frame_source.h"
#include "viewline/scenarios/ball_catching/config.h"
#include "viewline/sim/physics.h"
#include "viewline/sim/rig.h"

namespace viewline::scenarios {

/// One drawn throw.
struct ThrowDraw {
  Eigen::Vector3d release = Eigen::Vector3d::Zero(),  ///< release point, world, m
                  aim = Eigen::Vector3d::Zero();      ///< aim point in the box plane, world, m
  Eigen::Vector3d launch_velocity = Eigen::Vector3d::Zero();  ///< velocity at release, world, m/s
  double flight_time = 0.0;  ///< release to the aim point, s
  double distance = 0.0;     ///< release to the box plane along its normal, m
};

/// Draws a throw from the distribution (4 + 2 uniform draws from rng, in a fixed order).
ThrowDraw drawThrow(const BallCatchingConfig& cfg, core::Rng& rng);

/// The launch velocity that puts the ball centre at `aim` after `flight_time` with drag k
/// (Newton with a finite-difference Jacobian, from the drag-free solution).
Eigen::Vector3d solveLaunchVelocity(const Eigen::Vector3d& release, const Eigen::Vector3d& aim, double flight_time,
                                    const sim::DragBody& body);

/// The true crossing time of the flight with the plane through `point` with normal n (first sign
/// change on a 1 ms grid, then 60 bisections). Throws core::NumericalError when it never crosses.
double crossingTime(const sim::DragFlight& flight, const Eigen::Vector3d& point, const Eigen::Vector3d& n);

/// The box with its hole centred on `hole` (and the registration marker on its top when enabled).
void appendBox(const BallCatchingConfig& cfg, const Eigen::Matrix3d& R, const Eigen::Vector3d& hole,
               std::vector<sim::Primitive>& out);

/// The room and the box held still with its hole at `hole` (registration).
class StaticBoxWorld : public sim::World {
public:
  /// The box of `cfg` with its hole centre at `hole` (world, m) in `room` (both must outlive the world).
  StaticBoxWorld(const sim::Scene& room, const BallCatchingConfig& cfg, const Eigen::Vector3d& hole)
      : room_(room), cfg_(cfg), hole_(hole), R_(boxRotation(cfg.box_normal)) {}
  /// The room.
  const sim::Scene& staticScene() const override { return room_; }
  /// The box (and the marker), the same at every time.
  void dynamicObjects(double, std::vector<sim::Primitive>& out) const override { appendBox(cfg_, R_, hole_, out); }

private:
  const sim::Scene& room_;
  const BallCatchingConfig& cfg_;
  Eigen::Vector3d hole_;
  Eigen::Matrix3d R_;
};

/// The world of one throw: the room, the ball (or dart) on its flight, the box where the robot
/// holds it at time t (so the robot must have been commanded up to t before rendering).
class CatchWorld : public sim::World {
public:
  /// The throw `flight` and the box on `robot` in `room` (all must outlive the world).
  CatchWorld(const sim::Scene& room, const sim::DragFlight& flight, const BallCatchingConfig& cfg,
             const robots::CartesianRobot& robot)
      : room_(room), flight_(flight), cfg_(cfg), robot_(robot), R_(boxRotation(cfg.box_normal)) {}
  /// The room.
  const sim::Scene& staticScene() const override { return room_; }
  /// The ball (or dart) at time t (s) on its flight and the box where the robot holds it then.
  void dynamicObjects(double t, std::vector<sim::Primitive>& out) const override;

private:
  const sim::Scene& room_;
  const sim::DragFlight& flight_;
  const BallCatchingConfig& cfg_;
  const robots::CartesianRobot& robot_;
  Eigen::Matrix3d R_;
};

/// The free-running cameras of a throw (sim::CameraRig: own rate, random phase drawn from rng in
/// camera order, drift, jitter, drops, sensor noise, motion blur) for the active cameras.
std::vector<sim::SimCamera> throwCameras(const BallCatchingConfig& cfg, core::Rng& rng);

/// The simulator's renderer as a frame source: frames of a sim::CameraRig rendered from a
/// sim::World, in capture-time order, until `t_end` (captures at or after it end the source).
/// A frame can be taken at the end of its exposure (capture time + exposure / 2): by then the
/// world (the box on the robot) has been simulated over everything the image shows.
/// The true objects of the last frame (a simulator's privilege) are kept for the metrics.
class RigFrameSource : public runtime::FrameSource {
public:
  /// Frames of `cameras` (random phases from `rng`) rendering `world` until `t_end` (s).
  RigFrameSource(std::vector<sim::SimCamera> cameras, core::Rng& rng, const sim::RenderSettings& render,
                 const sim::World& world, double t_end);
  /// The number of cameras.
  std::size_t cameraCount() const override { return rig_.cameras().size(); }
  /// The end of the next frame's exposure (none after t_end).
  std::optional<core::Timestamp> nextReadyTime() const override;
  /// Renders the next frame in capture-time order and keeps its truth.
  std::optional<runtime::Frame> grab() override;
  /// The truth of the last frame grabbed (empty before the first).
  const std::vector<sim::ObjectTruth>& lastTruth() const { return last_truth_; }
  /// The truth entry of object `name` in the last frame, or nullptr.
  const sim::ObjectTruth* lastTruthOf(const std::string& name) const;

private:
  sim::CameraRig rig_;
  const sim::World& world_;
  double t_end_;
  std::vector<sim::ObjectTruth> last_truth_;
};

}  // namespace viewline::scenarios
