#pragma once
// The table-ball world (see table_ball.h for the geometry): the arm-held table and the rolling
// ball on a 1 ms physics tick, the wrist that tilts it (robots::SimulatedTableTilt behind the
// robots::TableTilt interface), the room, and the swaying head camera with its renderer, offered
// to the loop as a runtime::FrameSource so that a recording or a live camera can replace it.

#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "viewline/core/camera.h"
#include "viewline/core/random.h"
#include "viewline/robots/table_tilt.h"
#include "viewline/runtime/frame_source.h"
#include "viewline/runtime/scheduler.h"
#include "viewline/scenarios/table_ball/config.h"
#include "viewline/scenarios/table_ball/observer.h"
#include "viewline/sim/physics.h"
#include "viewline/sim/rig.h"
#include "viewline/sim/worlds.h"
#include "viewline/vision/apriltag_detector.h"

namespace viewline::scenarios {

/// Head sway: small rotations about the camera axes and a small translation, sums of sines at
/// incommensurate frequencies around f (deterministic; phases from the seed).
struct HeadSway {
  Eigen::Isometry3d c_M_w0;  ///< the camera's rest pose (world to camera)
  double amplitude,          ///< rad, rotation amplitude about x and y (half of it about z)
         f,                  ///< Hz, base frequency
         translation;        ///< m, translation amplitude per axis
  std::array<double, 6> phase{};  ///< rad, phases of the 3 rotation and 3 translation sines
  /// The swayed camera pose c_M_w at time t (s): the sway applied to c_M_w0.
  Eigen::Isometry3d at(double t) const;
};

/// The AprilTag layout of the simulated table (tags ids, sizes, and their poses in the table frame
/// in vpDetectorAprilTag's tag frame: sim::TableWorld::table_M_vispTag).
std::vector<vision::TagOnTable> tableTagLayout(const sim::TableWorld& world);

/// Event order of a table-ball session, the same in the simulated loop (loop.cpp) and on footage
/// (footage.cpp), so that both see a frame against the same physics ticks.
namespace table_ball_order {
/// Rank of a frame: at equal times it runs before the wrist's physics tick.
inline constexpr int kFrame = runtime::priority::Physics;
/// Rank of a physics tick (after a frame at the same time).
inline constexpr int kTick = runtime::priority::Physics + 1;
/// A frame ready at r sees the physics ticks that start before r − 1 ns (the 1 ms grid and the
/// capture times are rounded separately; a tick due at r itself simulates what follows it), and a
/// ramp is sent 1 ns before its start.
inline constexpr double kTimeTolerance = 1e-9;
}  // namespace table_ball_order

/// The simulated table-ball world: the tilting table and ball (physics at kTick), the wrist that
/// tilts it, the swaying head camera and the rendered scene. Neither copied nor moved.
class TableBallWorld {
public:
  /// Physics and command interpolation step, s.
  static constexpr double kTick = 1e-3;

  /// Builds everything from the config; randomness from `seed` (sway phases, room textures,
  /// camera effects and the head's rotation sensor, each on its own derived stream).
  TableBallWorld(const TableBallConfig& config, std::uint64_t seed);
  TableBallWorld(const TableBallWorld&) = delete;
  TableBallWorld& operator=(const TableBallWorld&) = delete;

  // --- physics -------------------------------------------------------------------------------
  /// One tick from time() to time() + kTick: the pushes due by the tick's end hit the ball, the
  /// table follows the wrist's actual tilt at the tick's end. Tick k starts at k · kTick
  /// (computed from k, not accumulated, so long runs do not drift).
  void step();
  /// Simulated time, s (ticks() · kTick).
  double time() const { return static_cast<double>(ticks_) * kTick; }
  /// Physics ticks done.
  long ticks() const { return ticks_; }
  /// The true table and ball state now (tilt, ball position and velocity in the table frame).
  const sim::TiltTableState& state() const { return table_.state(); }
  /// The recorded state at an earlier time (a frame's capture instant).
  sim::TiltTableState stateAt(double t) const { return table_.stateAt(t); }
  /// The table pose the arm's kinematics predict for given tilt angles.
  Eigen::Isometry3d tablePose(const Eigen::Vector2d& tilt) const { return table_.tablePose(tilt); }
  /// The wrist that tilts the table (the controller commands it; limits and delay apply).
  robots::TableTilt& wrist() { return wrist_; }

  // --- head camera ---------------------------------------------------------------------------
  /// The true camera the renderer uses (rest pose; the sway is applied per frame).
  const core::Camera& renderCamera() const { return camera_; }
  /// The camera the observer believes in (calibrated with a rig, else the render camera).
  const core::Camera& observerCamera() const { return obs_camera_; }
  /// The head's pose as the observer knows it at time t: the measured sway (neck joints / IMU)
  /// applied to the (calibrated) rest pose.
  Eigen::Isometry3d observerHeadPose(double t) const;
  /// The camera-to-ground rotation of that pose as the head's rotation sensor reads it
  /// (Gaussian rotation error of camera.ground_rotation_noise per axis, one draw per frame).
  Eigen::Matrix3d groundRotationReading(const Eigen::Isometry3d& c_M_w);
  /// The observer's configuration: the configured one, completed with what the world's design
  /// fixes (L, r, border height, tag layout).
  TableBallObserverConfig observerConfig() const;

  /// The head camera's rig (renders the frames: noise, blur, drops).
  sim::CameraRig& cameraRig() { return rig_; }
  /// The rendered scene: room, table, borders, tags and ball.
  const sim::TableWorld& scene() const { return scene_; }

private:
  HeadSway makeSway();  ///< draws the phases (construction only)
  const TableBallConfig cfg_;
  core::Rng rng_, room_rng_, rig_rng_, imu_rng_;
  sim::TiltTable table_;
  robots::SimulatedTableTilt wrist_;
  sim::TableWorld scene_;
  core::Camera camera_, obs_camera_;
  HeadSway sway_;
  sim::CameraRig rig_;
  long ticks_ = 0;
  std::size_t push_i_ = 0;
};

/// The head camera as a frame source over the renderer. A frame is ready at the end of its
/// exposure (capture_time + exposure / 2): everything it shows has been simulated by then. The
/// source ends at the first capture at or after `end`.
class RenderedHeadCamera final : public runtime::FrameSource {
public:
  /// `world` renders; both must outlive the source.
  RenderedHeadCamera(TableBallWorld& world, double exposure, double end);
  std::size_t cameraCount() const override { return 1; }
  std::optional<core::Timestamp> nextReadyTime() const override;
  std::optional<runtime::Frame> grab() override;
  /// The capture grab() took last, lost or not (a driver reports a lost frame's time stamp
  /// through the gap in its sequence numbers; the observer predicts to it).
  const sim::Capture& lastCapture() const { return last_; }

private:
  TableBallWorld& world_;
  double exposure_, end_;
  sim::Capture last_;
};

}  // namespace viewline::scenarios
