#pragma once
// What the world and camera nodes simulate, as library code so that a test (or a bench) can run
// the same simulation in one process and compare it with the nodes' result:
//  - WorldTruth: the throw of the ball-catching scenario (scenarios::drawThrow, the same seeded
//    draw as runThrow's first throw) released at a given time on the simulated clock;
//  - DetectionGenerator: a free-running camera (rate and clock drift of the scenario's camera,
//    phase drawn from the seed) that projects the true ball centre through the TRUE camera (the one
//    the simulator renders with) and adds white pixel noise; a unit-test-grade stand-in for
//    rendering + detection, fast enough for 16 cameras at 100 Hz on one machine;
//  - rigHash: the identity of a rig (what the estimators use), published by every node so that a
//    node configured with another rig is refused.

#include <Eigen/Core>
#include <cstdint>
#include <optional>

#include "viewline/core/camera.h"
#include "viewline/core/random.h"
#include "viewline/core/time.h"
#include "viewline/scenarios/ball_catching/config.h"
#include "viewline/sim/physics.h"

namespace viewline::nodes {

/// FNV-1a hash of the active cameras' estimator models (name, size, intrinsics, pose c_M_w): two
/// nodes with equal hashes use the same rig.
std::uint64_t rigHash(const scenarios::BallCatchingConfig& cfg);

/// The true ball of one throw on the simulated clock.
class WorldTruth {
public:
  /// The throw drawn as runThrow draws throw `index` of a session with `seed`, released at
  /// `release_time` s on the simulated clock.
  WorldTruth(const scenarios::BallCatchingConfig& cfg, std::uint64_t seed, double release_time, int index = 0);
  /// True while the ball flies (release to the crossing of the box plane + post_crossing_s).
  bool inFlight(core::Timestamp t) const { return t >= release_ && t <= t_end_; }
  /// The ball's state at t (only while inFlight(t)): p in m, v in m/s, world frame.
  sim::FlightState state(core::Timestamp t) const { return flight_.state(t - release_); }
  /// Time the ball crosses the box plane, s on the simulated clock.
  double crossingTime() const { return t_cross_; }
  /// End of the flight shown to the cameras, s.
  double endTime() const { return t_end_; }

private:
  double release_;
  sim::DragFlight flight_;  // on the throw's own clock (0 at the release), as runThrow's
  double t_cross_, t_end_;
};

/// One frame of a simulated camera: its number, capture stamp and (when seen) the noisy pixel.
struct GeneratedFrame {
  std::uint64_t frame_number = 0;  ///< counts every capture from 0 (gaps downstream: frames lost)
  core::Timestamp stamp = 0.0;     ///< capture stamp, s (the camera's clock: simulated time + offset)
  std::optional<Eigen::Vector2d> pixel;  ///< noisy pixel (u, v), px; empty: ball not in the image
  double sigma_px = 0.0;           ///< the noise std added, px (per axis)
};

/// A free-running camera that detects the true ball in its image (header comment).
class DetectionGenerator {
public:
  /// Camera `index` of cfg: rate cfg.throwRate(index), clock drift, phase drawn from
  /// deriveSeed(seed, 0x100 + index); pixel noise sigma_px per axis; stamps offset by clock_offset_s.
  DetectionGenerator(const scenarios::BallCatchingConfig& cfg, std::size_t index, std::uint64_t seed,
                     double sigma_px, double clock_offset_s = 0.0);
  /// Called with every tick of the simulated clock (in order) and the true ball position then
  /// (m, world frame; empty: no ball): a frame when a capture falls due at or before t (captured
  /// at t, the tick the camera sees; at most one per tick).
  std::optional<GeneratedFrame> onTick(core::Timestamp t, const std::optional<Eigen::Vector3d>& p_true);
  /// The camera's name in the rig.
  const std::string& name() const { return camera_.name; }

private:
  core::Camera camera_;
  std::size_t index_;
  std::uint64_t seed_;
  double period_, next_, sigma_, offset_;
  std::uint64_t frames_ = 0;
};

}  // namespace viewline::nodes
