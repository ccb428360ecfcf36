#pragma once
// The pan-tilt scenario's simulated world ([T]): what a real set-up would replace with hardware.
//
// Frame f = the unit's base frame of vpPtu46 (x forward, y left, z up). A vertical screen at
// `screen.distance` along +x_f, its centre at height `screen.center_height`; screen frame x right
// (−y_f), y down (−z_f), z into the screen (+x_f). A dark disc moves on it along a sim::ScreenPath
// (rectangle, circle, random polyline) at constant speed, hidden during the occlusion window.
// Rendered by sim::CameraRig (ray-cast, anti-aliased, sensor noise) through the camera on the
// simulated FLIR PTU-D46 (pose from vpPtu46 at the capture time, the TRUE mount and camera).
//
// [T]'s measurement noise: n_k ~ N(0, diag(σx², σy²)), σ_axis = noise_fraction · A_axis, where
// A_axis = (max − min) / 2 of the true path along that axis ("white noise of 10 % of the signal
// amplitude"), taken over one lap for the rectangle and circle, over the run for the random path.
//
// Random streams (all from the run's seed): the path (1), the rendering (2), [T]'s noise (3); both
// controllers see the same path, sensor noise and noise draws for the same frame index.

#include <Eigen/Geometry>
#include <cstdint>
#include <optional>

#include "viewline/core/random.h"
#include "viewline/robots/pan_tilt_kinematics.h"
#include "viewline/robots/simulated_pan_tilt.h"
#include "viewline/runtime/frame_source.h"
#include "viewline/scenarios/pan_tilt/config.h"
#include "viewline/sim/rig.h"
#include "viewline/sim/worlds.h"

namespace viewline::scenarios {

/// Per-axis amplitude A = (max − min)/2 of a path's true position over [0, duration] (m).
Eigen::Vector2d pathAmplitude(const sim::ScreenPath& path, double duration);

namespace pan_tilt {

/// Pose of the screen (x, y in its plane) in the unit's base frame f.
Eigen::Isometry3d screenPose(const PanTiltScenarioConfig& config);
/// The target's path of a seed (its own stream), generated for the run's duration + 10 s.
sim::ScreenPath makePath(const PanTiltScenarioConfig& config, std::uint64_t seed);
/// [T]'s noise std per axis (m) on this path (see the file comment).
Eigen::Vector2d noiseSigma(const PanTiltScenarioConfig& config, const sim::ScreenPath& path);
/// diag(σ²), kept positive definite for a path that does not move along an axis.
Eigen::Matrix2d noiseCovariance(const Eigen::Vector2d& sigma);

/// What the simulator knows to be true about one frame.
struct FrameTruth {
  Eigen::Vector2d plane = Eigen::Vector2d::Zero();  ///< target on the screen (m)
  Eigen::Vector2d px = Eigen::Vector2d::Zero();     ///< its projection in the true camera (px)
  double error_px = 0.0;                            ///< |px − true principal point|
};

/// Screen, target, occlusion, the simulated unit (pointing at the path's start plus the configured
/// offset) and the camera rig on it. Holds references into itself: neither copied nor moved.
class World {
public:
  /// Builds the world of `seed` (path, rendering and noise streams derived from it); config is not
  /// kept. With `hardware` (not owned, outliving the world) the camera rides on that unit: frames
  /// are rendered at the joints it reads when they are captured.
  World(const PanTiltScenarioConfig& config, std::uint64_t seed, robots::PanTiltUnit* hardware = nullptr);
  World(const World&) = delete;
  World& operator=(const World&) = delete;

  /// The target's path on the screen (m, screen frame).
  const sim::ScreenPath& path() const { return path_; }
  /// Pose of the screen in the unit's base frame f.
  const Eigen::Isometry3d& f_M_screen() const { return f_M_screen_; }
  /// [T]'s measurement noise std (x, y) on this path, m.
  const Eigen::Vector2d& sigma() const { return sigma_; }
  /// diag(σ²) of [T]'s noise (kept positive definite), m².
  const Eigen::Matrix2d& R() const { return R_; }
  /// [T]'s noise of the next frame (drawn for every frame, detected or not).
  Eigen::Vector2d drawNoise();
  /// The simulated unit (true mount; joints, limits, latency).
  robots::SimulatedPanTiltUnit& unit() { return unit_; }
  /// The unit the loop drives and the camera rides on: the hardware unit given at construction,
  /// else the simulated one.
  robots::PanTiltUnit& actuator() { return hardware_ != nullptr ? *hardware_ : unit_; }
  /// The unit as the controllers know it (calibrated camera mount).
  const robots::PanTiltKinematics& modelKinematics() const { return kin_model_; }
  /// The camera rig on the unit (true camera; renders the frames).
  sim::CameraRig& rig() { return rig_; }
  /// What the camera sees: screen and disc, the disc hidden during the occlusion window.
  const sim::World& scene() const { return occluded_; }
  /// Truth at capture time tc, through the camera as it was at capture (true pose).
  FrameTruth truth(const core::Camera& camera_at_capture, double tc) const;
  /// The true camera's principal point (px): the image error is measured from it.
  const Eigen::Vector2d& principal() const { return principal_; }
  double occlusionStart() const { return occ0_; }  ///< 1e300 without one
  double occlusionEnd() const { return occ1_; }    ///< s, end of the occlusion window (exclusive)
  double exposure() const { return exposure_; }    ///< s, the camera's exposure (0: no motion blur)

private:
  class Occluded : public sim::World {
  public:
    Occluded(const sim::World& inner, double t0, double t1) : inner_(inner), t0_(t0), t1_(t1) {}
    const sim::Scene& staticScene() const override { return inner_.staticScene(); }
    void dynamicObjects(double t, std::vector<sim::Primitive>& out) const override;
    sim::Lighting lighting() const override { return inner_.lighting(); }
    std::uint64_t staticVersion() const override { return inner_.staticVersion(); }

  private:
    const sim::World& inner_;
    double t0_, t1_;
  };

  core::Rng path_rng_, render_rng_, noise_rng_;
  sim::ScreenPath path_;
  Eigen::Isometry3d f_M_screen_;
  sim::ScreenWorld screen_;
  double occ0_, occ1_;
  Occluded occluded_;
  Eigen::Vector2d sigma_;
  Eigen::Matrix2d R_;
  robots::PanTiltKinematics kin_, kin_model_;
  robots::SimulatedPanTiltUnit unit_;
  robots::PanTiltUnit* hardware_ = nullptr;  // not owned
  sim::CameraRig rig_;
  Eigen::Vector2d principal_;
  double exposure_;
};

/// The renderer as a frame source: captures of the world's camera rig, in time order. A live
/// camera or a recording replaces it without touching the loop; the simulator's extra knowledge
/// (the camera's true pose at capture, for the truth) stays here.
class RendererSource : public runtime::FrameSource {
public:
  /// `frames`: how many captures (dropped ones included) before the source ends.
  RendererSource(World& world, std::size_t frames);
  std::size_t cameraCount() const override { return 1; }
  /// The end of the next frame's exposure: everything it shows has been simulated by then.
  std::optional<core::Timestamp> nextReadyTime() const override;
  std::optional<runtime::Frame> grab() override;
  /// The camera (true pose) of the last frame grabbed.
  const core::Camera& lastCamera() const { return last_camera_; }

private:
  World& world_;
  std::size_t remaining_;
  core::Camera last_camera_;
};

}  // namespace pan_tilt
}  // namespace viewline::scenarios
