#pragma once
// A rig of free-running simulated cameras, each with its own rate, phase, clock drift,
// resolution, effects and (optionally moving) pose, producing time-stamped frames of a World
// in capture-time order.
//
// Schedule of camera i after reset(t_start): frame k is captured (middle of the exposure) at
//     t_k = t_start + phase + k (1 + drift) / rate + ε_k,   ε_k ~ N(0, trigger_jitter²)
// (ε clamped to ±0.45 period) and reported with the stamp  s_k = t_k + N(0, stamp_jitter²).
// A frame is dropped with probability drop_probability; its sequence number is used up, so
// gaps in Frame::sequence reveal the drops (as with real cameras). Ground truth is taken at
// the true capture time t_k.
//
// Randomness: at construction one value is drawn from the rng passed in; each camera then has
// its own streams derived from it (schedule, image effects), so adding a camera or switching an
// effect on does not change the other cameras' draws. reset() rewinds every stream: running the
// same interval twice gives identical frames.

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "viewline/core/camera.h"
#include "viewline/core/random.h"
#include "viewline/core/time.h"
#include "viewline/sim/effects.h"
#include "viewline/sim/renderer.h"

namespace viewline::sim {

/// Free-running clock of a simulated camera: rate, phase and drift.
struct CameraClock {
  double rate = 50.0;    ///< frames per second, > 0
  double phase = 0.0;    ///< s, first capture after reset, >= 0
  double drift = 0.0;    ///< relative period error of the free-running clock (e.g. 50e-6), > -1
};

/// One simulated camera of a rig: camera model, clock, imaging effects and an optional moving pose.
struct SimCamera {
  core::Camera camera;           ///< intrinsics, size, and pose (used when pose_at is empty)
  CameraClock clock;  ///< capture schedule
  ImagingEffects effects;  ///< noise, blur, illumination, occlusion, frame faults
  /// Optional moving camera: c_M_w at time t (pan-tilt head, mobile robot).
  std::function<Eigen::Isometry3d(double t)> pose_at;
};

/// A rendered frame of a simulated camera, with its time stamps and the ground truth of named objects.
struct Frame {
  std::size_t camera_index = 0;  ///< index of the camera in the rig
  std::string camera_name;  ///< name of the camera
  std::uint64_t sequence = 0;        ///< per camera, counts dropped frames too
  core::Timestamp stamp = 0.0;       ///< reported capture time (with jitter), s
  double capture_time = 0.0;         ///< true capture time (middle of the exposure), s
  core::Camera camera;               ///< the camera as it was at capture (true pose)
  cv::Mat image;                     ///< CV_8UC3 BGR, camera.width x camera.height
  std::vector<ObjectTruth> truth;    ///< named objects of the world (+ nothing for the occluder)
  /// The truth entry of a named object, or nullptr.
  const ObjectTruth* find(const std::string& name) const;
};

/// A scheduled capture (no image): what the rig will produce next.
struct Capture {
  std::size_t camera_index = 0;  ///< index of the camera in the rig
  std::uint64_t sequence = 0;  ///< per-camera frame number (dropped frames use theirs up)
  double capture_time = 0.0;  ///< true capture time (middle of the exposure), s
  core::Timestamp stamp = 0.0;  ///< reported capture time (with jitter), s
  bool dropped = false;  ///< the frame will be lost
};

/// A rig of free-running simulated cameras producing time-stamped frames of a World in capture-time order.
class CameraRig {
public:
  /// Throws core::InvalidInput (naming camera and field) for bad clocks, effects or cameras.
  CameraRig(std::vector<SimCamera> cameras, core::Rng& rng, const RenderSettings& render = {});

  /// Restart every camera's clock and random streams at t_start.
  void reset(double t_start = 0.0);

  /// The next capture in time order (dropped ones included, flagged), without rendering it.
  const Capture& peek() const;
  /// Advances past the next capture; renders it unless it is dropped (then returns nullopt).
  std::optional<Frame> captureNext(const World& world);

  /// reset(t0), then delivers every non-dropped frame with capture time in [t0, t1) to `sink`
  /// in capture-time order (ties: camera order). Returns the number of frames delivered.
  std::size_t run(const World& world, double t0, double t1, const std::function<void(Frame&&)>& sink);

  /// The captures of [t0, t1) (dropped ones flagged) without rendering; leaves the rig reset.
  std::vector<Capture> schedule(double t0, double t1);

  /// The cameras of the rig.
  const std::vector<SimCamera>& cameras() const { return cameras_; }
  /// Frames dropped per camera since the last reset.
  const std::vector<std::uint64_t>& dropped() const { return dropped_; }
  /// The renderer (its settings and caches).
  Renderer& renderer() { return renderer_; }

private:
  struct Stream {
    core::Rng clock_rng;   ///< schedule: trigger jitter, stamp jitter, drops
    core::Rng effect_rng;  ///< pixels: noise offsets, occlusion directions
    std::uint64_t k = 0;   ///< index of the next capture
    Capture next;
  };
  void scheduleNext(std::size_t i);
  std::size_t nextIndex() const;

  std::vector<SimCamera> cameras_;
  std::uint64_t seed_;
  Renderer renderer_;
  std::vector<Stream> streams_;
  std::vector<NoisePool> noise_;
  std::vector<std::uint64_t> dropped_;
  double t_start_ = 0.0;
};

}  // namespace viewline::sim
