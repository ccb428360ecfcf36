#pragma once
// The ball-catching per-frame work, outside the scenario loop so that it can be timed and its
// allocations counted without the renderer: the frames of a real throw (scenarios::runBallCatching,
// the default config, its renderer and cameras) are recorded once, then replayed through the same
// parts the throw loop wires (scenarios/ball_catching/loop.cpp: ThrowLoop::measure and tick):
//
//   predicted pixel (tracker.predictAt, camera.project) -> vision::BallDetector (window around
//   it, or the full frame) -> tracking::ViewlineTracker::submit -> its outcome ->
//   (when fused) scenarios::PlannerInput::after (the flight fit of the track's images) ->
//   planning::CatchPlanner::update -> CatchPlanner::setpoint.
//
// The planner update and the set point run on every frame here (in the scenario they run on the
// control tick): an upper bound of the per-frame work.

#include <cmath>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "viewline/io/config_edit.h"
#include "viewline/planning/catch_planner.h"
#include "viewline/robots/cartesian_robot.h"
#include "viewline/scenarios/ball_catching.h"
#include "viewline/scenarios/ball_catching/planner_input.h"
#include "viewline/tracking/tracker.h"
#include "viewline/vision/ball_detector.h"

namespace viewline::latency {

/// One recorded camera frame of a throw.
struct CatchRecordedFrame {
  int throw_index = 0;     ///< throws have their own clocks (from 0): the pipeline restarts
  std::size_t camera = 0;  ///< index into the estimator cameras
  double t = 0.0;          ///< capture time, s
  cv::Mat image;           ///< BGR, as rendered
};

/// The default ball-catching config (registration off: the estimator cameras are the rig's).
inline scenarios::BallCatchingConfig catchConfig(const std::string& path) {
  scenarios::BallCatchingConfig cfg = scenarios::loadBallCatchingConfig(io::loadConfigWithValues(path, {}));
  cfg.registration.enabled = false;
  cfg.threads = 1;
  return cfg;
}

/// Renders `throws` throws of `cfg` and keeps every frame (at most `max_frames`).
inline std::vector<CatchRecordedFrame> recordCatchFrames(const scenarios::BallCatchingConfig& cfg, int throws,
                                                         std::uint64_t seed, std::size_t max_frames) {
  std::vector<CatchRecordedFrame> frames;
  scenarios::CatchHooks hooks;
  hooks.on_frame = [&](const scenarios::CatchFrame& f) {
    if (frames.size() < max_frames) frames.push_back({f.throw_index, f.camera, f.t, f.image->clone()});
    return true;
  };
  scenarios::runBallCatching(cfg, throws, seed, hooks);
  return frames;
}

/// Detector per camera, tracker and planner of one throw, as ThrowLoop wires them.
class CatchPipeline {
public:
  /// The parts of one throw for `cfg` (which must outlive the pipeline).
  explicit CatchPipeline(const scenarios::BallCatchingConfig& cfg)
      : cfg_(cfg),
        robot_(cfg.robot),
        planner_(cfg.plannerConfig(), robot_),
        tracker_(cameras(cfg), cfg.tracker),
        planner_input_(cfg, tracker_.cameras()) {
    for (const auto& c : tracker_.cameras()) detectors_.emplace_back(cfg.detector, c);
    reset();
  }

  /// A new throw: tracker and planner start over (the detectors keep their buffers).
  void reset() {
    throw_index_ = -1;
    tracker_.reset();
    robot_.reset(0.0);
    planner_.reset(0.0, cfg_.robot.home);
    planner_input_.reset();
    next_id_ = 1;
  }

  /// CPU time of the stages of one frame, s (filled when process() is given a clock).
  struct StageTimes {
    double detect = 0.0;  ///< prediction of the pixel + detection
    double track = 0.0;   ///< submit + outcome
    double plan = 0.0;    ///< flight fit and planner update (when fused) + set point
  };

  /// One frame (a frame of another throw than the last restarts tracker and planner);
  /// `acquisition`: no predicted pixel (the detector searches the full frame).
  /// Returns whether the detector found the ball in the window around the prediction. With
  /// `clock` (a function returning seconds) the stages are timed into `stages`.
  bool process(const CatchRecordedFrame& f, bool acquisition, double (*clock)() = nullptr,
               StageTimes* stages = nullptr) {
    if (f.throw_index != throw_index_) {
      if (throw_index_ >= 0) reset();
      throw_index_ = f.throw_index;
    }
    const double c0 = clock ? clock() : 0.0;
    const std::size_t ci = f.camera;
    std::optional<Eigen::Vector2d> predicted;
    if (!acquisition && tracker_.initialised()) {
      const double tp = std::max(f.t, tracker_.state().t());
      if (auto uv = tracker_.cameras()[ci].project(tracker_.predictAt(tp).x().head<3>())) predicted = *uv;
    }
    const auto det = detectors_[ci].detect(f.image, f.t, predicted);
    const double c1 = clock ? clock() : 0.0;
    bool in_window = false, fused = false;
    tracking::ImageMeasurement m;
    if (det.ok()) {
      in_window = det.value().used_roi;
      const double sigma = std::max(cfg_.sigma_px_floor, std::sqrt(0.5 * det.value().pixel_covariance.trace()));
      m = {next_id_++, ci, f.t, det.value().pixel, sigma};
      if (tracker_.submit(m) == tracking::Refusal::None) {
        const auto o = tracker_.outcome(m.id);
        fused = o && o->fate == tracking::Fate::Fused && tracker_.initialised();
      }
    }
    const double c2 = clock ? clock() : 0.0;
    if (fused) {
      const planning::PlannerUpdate u = planner_.update(f.t, planner_input_.after(m, tracker_));
      crossings_ += u.crossing.has_value();
    }
    const robots::CartesianState sp = planner_.setpoint(f.t);
    sink_ += sp.p.x();
    if (clock && stages) {
      const double c3 = clock();
      *stages = {c1 - c0, c2 - c1, c3 - c2};
    }
    return in_window;
  }

  /// The tracker (initialised() tells whether a track is held).
  const tracking::ViewlineTracker& tracker() const { return tracker_; }
  /// Planner updates that predicted a crossing (keeps the work observable).
  std::size_t crossings() const { return crossings_; }

private:
  static std::vector<core::Camera> cameras(const scenarios::BallCatchingConfig& cfg) {
    std::vector<core::Camera> out;
    for (std::size_t i = 0; i < cfg.activeCameras(); ++i) out.push_back(cfg.cameras[i].estimatorCamera());
    return out;
  }

  const scenarios::BallCatchingConfig& cfg_;
  robots::SimulatedCartesianRobot robot_;
  planning::CatchPlanner planner_;
  tracking::ViewlineTracker tracker_;
  scenarios::PlannerInput planner_input_;  // the flight fit the planner predicts from
  std::vector<vision::BallDetector> detectors_;
  std::uint64_t next_id_ = 1;
  int throw_index_ = -1;
  std::size_t crossings_ = 0;
  double sink_ = 0.0;
};

}  // namespace viewline::latency
