#pragma once
// The ball-catching rig as DDS nodes, one process each (apps/viewline_node runs one role):
//
//   world    simulated time on rt/clock (ticks of tick_s, paced at `realtime` x wall clock) and
//            the true ball on rt/viewline/truth; waits until `expect` nodes follow its clock, runs
//            `throws` episodes of `duration_s` of simulated time (throw i of the session is the
//            in-process session's throw i, released release_s into its episode, announced on
//            rt/viewline/episode), then publishes Finished in its health (every node ends). It
//            scores each throw as the in-process loop does (scenarios::scoreThrow's rules): the
//            robot's state at the true crossing against the clearance, and the reachability
//            oracle from the first detection of the ball
//   camera   a free-running camera over the world's truth publishing rt/viewline/detections: the
//            generator's noisy projection (nodes::DetectionGenerator), or (render) the image
//            rendered by the simulator and the scenario's ball detector; its writer asserts
//            liveliness (lease dds::Qos::kCameraLeaseS)
//   tracker  viewline's multi-view tracker, the flight fit and the catch planner, built from the
//            scenario config as the ball-catching loop builds them, afresh for every episode;
//            publishes rt/viewline/track and, every control
//            period of simulated time, rt/viewline/setpoint; reports each camera's delivery delay
//            and notes a camera that leaves (liveliness lost)
//   robot    the scenario's simulated Cartesian robot executing the set points, back at home at
//            each episode's start; publishes rt/viewline/robot_state; halts when set points miss
//            their deadline
//
// Time: every node follows the world's simulated clock (the latest rt/clock sample, advanced by
// the wall time elapsed since it times `realtime`). Every node publishes its health on
// rt/viewline/health with the rig hash of its config (nodes::rigHash); a camera whose rig differs
// from the tracker's is refused by the tracker (its detections are dropped, the tracker says so)
// and ends itself with a message naming both hashes.
//
// Each run function returns the node's summary (JSON, also written to summary_path when set) and
// ends on the world's Finished, on SIGINT/SIGTERM (core::interruptRequested) or after max_wall_s.

#include <cstdint>
#include <string>
#include <nlohmann/json.hpp>

#include "viewline/scenarios/ball_catching/config.h"

namespace viewline::nodes {

/// Options shared by the roles (apps/viewline_node's flags).
struct NodeOptions {
  std::size_t camera = 0;        ///< camera role: index of the camera in the config
  std::uint64_t seed = 1;        ///< seeds the throw, camera phases and pixel noise
  int domain = -1;               ///< DDS domain id (< 0: the one CYCLONEDDS_URI configures)
  double realtime = 1.0;         ///< simulated seconds per wall second
  double tick_s = 0.002;         ///< world: simulated clock period, s
  double duration_s = 1.5;       ///< world: simulated time to run per throw (one episode), s
  int throws = 1;                ///< world: throws in the session, one episode of duration_s each
  double release_s = 0.2;        ///< world: release time of the throw on the simulated clock, s
  int expect = 0;                ///< world: nodes that must follow the clock before it starts
  double pixel_sigma = 0.5;      ///< camera: pixel noise std, px
  double clock_offset_s = 0.0;   ///< camera: error of its clock (added to its capture stamps), s
  /// camera: render each frame (the scenario's room, the box at home, the ball at the world's
  /// truth; sensor noise noise_sigma) and run the scenario's ball detector on it, instead of the
  /// generator's noisy projection
  bool render = false;
  double setpoint_deadline_s = 0.1;  ///< set-point deadline, s of wall time (robot halts past it)
  double max_wall_s = 60.0;      ///< any node ends after this much wall time, s
  std::string summary_path;      ///< JSON summary written here at the end ("" : none)
  /// tracker: CSV written here with one row per fused detection ("" : none): the update time and
  /// the detection's camera, capture stamp and delay (s of simulated time), the ball's estimated
  /// world position (m) and its standard deviation (m, root of the position covariance's trace)
  std::string track_log_path;
};

/// The world node (header comment); returns its summary.
nlohmann::json runWorldNode(const scenarios::BallCatchingConfig& cfg, const NodeOptions& opt);
/// A camera node; returns its summary. Throws core::Error when the tracker's rig differs.
nlohmann::json runCameraNode(const scenarios::BallCatchingConfig& cfg, const NodeOptions& opt);
/// The tracker node; returns its summary (final estimate, per-camera delivery, cameras that left).
nlohmann::json runTrackerNode(const scenarios::BallCatchingConfig& cfg, const NodeOptions& opt);
/// The robot node; returns its summary (set points, halt and its latency).
nlohmann::json runRobotNode(const scenarios::BallCatchingConfig& cfg, const NodeOptions& opt);

}  // namespace viewline::nodes
