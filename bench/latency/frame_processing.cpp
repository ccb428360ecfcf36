// Per-frame processing (detect + track + plan, excluding capture and rendering), thread CPU time
// on one core, and the scaling of the tracker with the number of cameras; with --check, the
// latency budget of docs/results.md ("Latency"): exit status 1 when a measured p99 is more than
// 20 % over its budget (run before a release; not in CI, whose timings are noisy).
//
// Table ball (320x240, config/table_ball.yaml): the frames of the first --record-seconds (6 s)
// of the scenario, replayed through the observer (table and ball detection, rolling-ball filter)
// and the controller.
// Pan-tilt (640x480, config/pan_tilt_rectangle.yaml): the predictive controller's frames of the
// first --record-seconds (6 s), replayed through detection, back-projection, target filter and law.
// Every frame is kept (0.9 MB each): 6 s end before the filter's steady state (the legs' corner
// evidence starts after the first corner); --pan-tilt-only --record-seconds 30 covers it.
// Ball catching (656x480, the default config's two cameras): the frames of real throws are
// recorded from the scenario (catch_pipeline.h) and replayed through detector, tracker and
// planner, pass after pass (the tracker and planner restart at each pass), until --frames frames
// are timed:
//  - tracking: the detector searches the window around the tracker's prediction; the frames it
//    found the ball in the window form the "window" sample, the others (the tracker's first
//    frames, frames without the ball) the "full frame" one;
//  - acquisition: no prediction, every frame searched whole.
// Scaling: K cameras on a circle 6 m around a ballistic flight, each at 100 Hz with its own phase,
// submit their pixels (σ 0.5 px) to one ViewlineTracker for --scaling-seconds of data; the CPU
// time per second of data is the fraction of one core; a least-squares line over K = 1..64 gives
// the cost per camera and the residual.
//
//   nice -n 10 build/bench/latency_frames [--frames 10000] [--scaling-seconds 2] [--throws 2]
//       [--record-seconds 6] [--config config/ball_catching.yaml] [--check] [--pan-tilt-only]
//       [--table-ball-only] [--stages]
// --pan-tilt-only: the pan-tilt rows alone (for profiling that pipeline; no budget check).
// --table-ball-only: the table-ball rows alone (no budget check); --stages adds the table ball's
// fast-path breakdown by stage (its clock reads add a little to the totals: the budget check
// runs without it).

#include <Eigen/Geometry>
#include <opencv2/core/utility.hpp>

#include <algorithm>
#include <cmath>
#include <optional>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "catch_pipeline.h"
#include "latency_stats.h"
#include "viewline/control/table_balancer.h"
#include "viewline/core/frames.h"
#include "viewline/core/random.h"
#include "viewline/scenarios/pan_tilt/loop.h"
#include "viewline/scenarios/pan_tilt/telemetry.h"
#include "viewline/scenarios/pan_tilt/world.h"
#include "viewline/scenarios/pan_tilt_scenario.h"
#include "viewline/scenarios/table_ball.h"
#include "viewline/scenarios/table_ball/world.h"

#ifndef VIEWLINE_SOURCE_DIR
#error "VIEWLINE_SOURCE_DIR must name the source tree (for the default config)"
#endif

namespace {

using namespace viewline;

struct Budget {
  const char* what;
  double budget_s;  ///< p99 budget
  double measured_s;
};

struct CatchFigures {
  latency::Stats window, full_in_tracking, acquisition;
  latency::Stats detect_window, track_window, plan_window;
  std::size_t recorded = 0;
};

CatchFigures ballCatching(const std::string& config, int throws, std::size_t frames_wanted) {
  const scenarios::BallCatchingConfig cfg = latency::catchConfig(config);
  const auto frames = latency::recordCatchFrames(cfg, throws, 1, 400);
  if (frames.empty()) throw core::Error("ball catching: the throws produced no frames");
  CatchFigures out;
  out.recorded = frames.size();
  latency::CatchPipeline pipe(cfg);
  std::vector<double> window, full, acq, dw, tw, pw;
  for (const bool acquisition : {false, true}) {
    pipe.reset();
    for (const auto& f : frames) pipe.process(f, acquisition);  // warm-up pass (buffers, caches)
    std::size_t timed = 0;
    while (timed < frames_wanted) {
      pipe.reset();
      for (const auto& f : frames) {
        latency::CatchPipeline::StageTimes st;
        const double t0 = latency::threadCpuNow();
        const bool in_window = pipe.process(f, acquisition, &latency::threadCpuNow, &st);
        const double dt = latency::threadCpuNow() - t0;
        ++timed;
        if (acquisition) {
          acq.push_back(dt);
        } else if (in_window) {
          window.push_back(dt);
          dw.push_back(st.detect);
          tw.push_back(st.track);
          pw.push_back(st.plan);
        } else {
          full.push_back(dt);
        }
      }
    }
  }
  out.window = latency::summarise(window);
  out.full_in_tracking = latency::summarise(full);
  out.acquisition = latency::summarise(acq);
  out.detect_window = latency::summarise(dw);
  out.track_window = latency::summarise(tw);
  out.plan_window = latency::summarise(pw);
  return out;
}

// ---- table ball ------------------------------------------------------------------------------

struct TableFrame {
  double t = 0.0;
  cv::Mat image;
  core::Camera camera;  ///< the observer's camera at capture
  Eigen::Vector2d tilt = Eigen::Vector2d::Zero();
  Eigen::Vector2d setpoint = Eigen::Vector2d::Zero();
};

// Frames of the default table-ball run (first `seconds`), replayed through the observer (table
// and ball detection, rolling-ball filter) and the controller, as the loop calls them
// (scenarios/table_ball/loop.cpp): c_R_w from the capture pose, the nominal table pose from the
// arm's kinematics at the true tilt.
struct TableBallFigures {
  latency::Stats total;     ///< every frame
  latency::Stats tracked;   ///< frames of the fast path (edge tracking)
  latency::Stats detected;  ///< frames of the full detection (first frame of a pass, fast path lost)
  /// Fast-path frames by stage: edge tracking, ball window, PnP refine, pose filter + tilt + ball
  /// on the table, rolling-ball filter, controller.
  latency::Stats fast_edges, fast_ball, fast_pose, fast_geometry, fast_filter, fast_control;
};

// With `stages`, the fast-path frames are also timed stage by stage (the clock reads add a little
// to the totals; the budget check runs without them).
TableBallFigures tableBall(const std::string& config, double seconds, std::size_t frames_wanted, std::size_t& recorded,
                           bool stages) {
  scenarios::TableBallConfig cfg = scenarios::tableBallConfigFromYaml(io::loadConfigWithValues(config, {}));
  cfg.duration = seconds;
  cfg.time_reference = false;
  std::vector<TableFrame> frames;
  scenarios::TableBallHooks hooks;
  hooks.on_frame = [&](const scenarios::TableBallFrameView& v) {
    if (v.image && v.camera && v.observer)
      frames.push_back({v.observer->t, v.image->clone(), *v.camera, v.tilt, v.setpoint});
    return true;
  };
  scenarios::runTableBall(cfg, 1, hooks);
  if (frames.empty()) throw core::Error("table ball: the run produced no frames");
  recorded = frames.size();
  scenarios::TableBallWorld world(cfg, 1);  // kinematics (table pose), observer config, wrist
  std::vector<double> times, tracked, detected;
  std::vector<double> s_edges, s_ball, s_pose, s_geometry, s_filter, s_control;
  std::size_t timed = 0;
  bool warm = false;
  while (timed < frames_wanted) {
    scenarios::TableBallObserver observer(world.observerCamera(), world.observerConfig());
    control::TableBalancer controller(cfg.controllerConfig(world.wrist()));
    double sink = 0.0;
    for (const auto& f : frames) {
      const Eigen::Matrix3d c_R_w = f.camera.c_M_w.rotation();
      const Eigen::Isometry3d c_M_t_nominal = f.camera.c_M_w * world.tablePose(f.tilt);
      scenarios::ObserverStageTimes st;
      const double t0 = latency::threadCpuNow();
      const scenarios::ObserverFrame& of =
          observer.process(f.image, f.t, c_R_w, c_M_t_nominal, stages ? &latency::threadCpuNow : nullptr, &st);
      const double t1 = stages ? latency::threadCpuNow() : 0.0;
      if (of.estimate_valid) {
        const control::TiltRamp r = controller.update(f.t, Eigen::Vector2d(of.x[0], of.x[2]),
                                                      Eigen::Vector2d(of.x[1], of.x[3]), f.setpoint);
        sink += r.rate.x();
      }
      const double t2 = latency::threadCpuNow();
      const double dt = t2 - t0;
      if (warm) {
        times.push_back(dt);
        (of.tracked ? tracked : detected).push_back(dt);
        if (stages && of.tracked) {
          s_edges.push_back(st.table);
          s_ball.push_back(st.ball);
          s_pose.push_back(st.pose);
          s_geometry.push_back(st.geometry);
          s_filter.push_back(st.filter);
          s_control.push_back(t2 - t1);
        }
        ++timed;
      }
    }
    warm = true;  // the first pass warms buffers and caches
    if (!std::isfinite(sink)) throw core::Error("table ball: non-finite controller output");
  }
  TableBallFigures out;
  out.total = latency::summarise(times);
  out.tracked = latency::summarise(tracked);
  out.detected = latency::summarise(detected);
  if (stages) {
    out.fast_edges = latency::summarise(s_edges);
    out.fast_ball = latency::summarise(s_ball);
    out.fast_pose = latency::summarise(s_pose);
    out.fast_geometry = latency::summarise(s_geometry);
    out.fast_filter = latency::summarise(s_filter);
    out.fast_control = latency::summarise(s_control);
  }
  return out;
}

// ---- pan-tilt ---------------------------------------------------------------------------------

struct PanTiltFrame {
  double t = 0.0;  ///< capture time
  cv::Mat image;
  Eigen::Vector2d q = Eigen::Vector2d::Zero(), qdot = Eigen::Vector2d::Zero();  ///< joints at the command
};

// Keeps the images and joint readings of the predictive controller's run.
class PanTiltRecorder final : public scenarios::pan_tilt::FrameSink {
public:
  explicit PanTiltRecorder(std::size_t max_frames) : max_(max_frames) {}
  void frame(const scenarios::pan_tilt::FrameRecord& r) override {
    if (r.image && frames.size() < max_) frames.push_back({r.t, r.image->clone(), r.q, r.qdot});
  }
  std::vector<PanTiltFrame> frames;

private:
  std::size_t max_;
};

// Frames of the default pan-tilt run (rectangle path), replayed through what the loop does per
// frame (scenarios/pan_tilt/loop.cpp): [T]'s screen-target detector, the back-projection onto
// the screen through the camera at the joint reading, the predictive controller's observe()
// (the constant-speed-leg target filter) and command(). The [T] measurement noise is left out
// (a draw), the rest is the same work.
struct PanTiltFigures {
  latency::Stats total, detect, filter, law;
  std::size_t windowed = 0;  ///< timed frames the detector answered from its window (no full-frame pass)
};

PanTiltFigures panTilt(const std::string& config, double seconds, std::size_t frames_wanted, std::size_t& recorded) {
  scenarios::PanTiltScenarioConfig cfg = scenarios::loadPanTiltScenarioConfig(io::loadConfigWithValues(config, {}));
  cfg.duration = seconds;
  cfg.metrics_start = std::min(cfg.metrics_start, 0.5 * seconds);  // scoring only; short recordings
  cfg.run_baseline = false;
  PanTiltRecorder rec(static_cast<std::size_t>(std::ceil(seconds * cfg.fps)) + 20);  // every frame of the run
  scenarios::PanTiltRunIo io;
  io.frames = &rec;
  scenarios::runPanTilt(cfg, 1, scenarios::PanTiltControllerKind::Predictive, io);
  if (rec.frames.empty()) throw core::Error("pan-tilt: the run produced no frames");
  recorded = rec.frames.size();
  scenarios::pan_tilt::World world(cfg, 1);
  const double latency = world.unit().commandLatency();
  const double period = 1.0 / cfg.fps;
  const auto& kin = world.modelKinematics();
  core::Camera model_cam = scenarios::panTiltModelCamera(cfg);
  const Eigen::Isometry3d screen_M_f = world.f_M_screen().inverse();
  std::vector<double> times, t_detect, t_filter, t_law;
  std::size_t timed = 0, windowed = 0;
  bool warm = false;
  while (timed < frames_wanted) {
    vision::ScreenTargetDetector detector(cfg.detector);
    control::PredictiveConfig pc = cfg.control;
    pc.filter.particle_seed = core::deriveSeed(1, 78);
    control::PredictivePanTiltController ctrl(pc, cfg.unit.limits, latency, world.f_M_screen(), kin);
    std::vector<robots::IssuedCommand> recent;
    double sink = 0.0;
    std::optional<Eigen::Vector2d> last_px;  // the loop's prediction: the last detection's pixel
    for (const auto& f : rec.frames) {
      const double t0 = latency::threadCpuNow();
      control::TargetObservation obs;
      obs.stamp = f.t;
      const auto det = detector.detect(f.image, f.t, last_px);
      last_px.reset();
      if (det.ok()) last_px = det.value().pixel;
      model_cam.c_M_w = kin.c_M_f(f.q);
      if (det.ok()) {
        const Eigen::Vector3d o_s = screen_M_f * model_cam.center_w();
        const Eigen::Vector3d d_s = screen_M_f.linear() * model_cam.rayThroughPixel_w(det.value().pixel);
        if (d_s.z() > 1e-9) {
          const Eigen::Vector3d hit = o_s + (-o_s.z() / d_s.z()) * d_s;
          const Eigen::Vector3d meas_c = model_cam.toCamera(world.f_M_screen() * Eigen::Vector3d(hit.x(), hit.y(), 0.0));
          obs.detected = meas_c.z() > 0.0;
          obs.plane = hit.head<2>();
          obs.plane_cov = world.R();
          obs.feature = Eigen::Vector2d(meas_c.x() / meas_c.z(), meas_c.y() / meas_c.z());
        }
      }
      const double t1 = latency::threadCpuNow();
      ctrl.observe(obs);
      const double t2 = latency::threadCpuNow();
      control::ControlInput in;
      in.t = f.t + cfg.processing_delay;
      in.joints = {in.t, f.q, f.qdot};
      in.recent = recent;
      in.period = period;
      const control::ControlOutput out = ctrl.command(in);
      recent.push_back({in.t, out.qdot});
      if (recent.size() > 4) recent.erase(recent.begin());
      sink += out.qdot.x();
      const double t3 = latency::threadCpuNow();
      if (warm) {
        times.push_back(t3 - t0);
        t_detect.push_back(t1 - t0);
        t_filter.push_back(t2 - t1);
        t_law.push_back(t3 - t2);
        windowed += detector.usedWindow() ? 1 : 0;
        ++timed;
      }
    }
    warm = true;
    if (!std::isfinite(sink)) throw core::Error("pan-tilt: non-finite command");
  }
  return {latency::summarise(times), latency::summarise(t_detect), latency::summarise(t_filter), latency::summarise(t_law),
          windowed};
}

// ---- scaling ---------------------------------------------------------------------------------

struct ScalingPoint {
  int cameras = 0;
  double core_fraction = 0.0;  ///< CPU seconds per second of data
  std::size_t submitted = 0, fused = 0;
};

std::vector<core::Camera> ringCameras(int k) {
  std::vector<core::Camera> cams;
  for (int c = 0; c < k; ++c) {
    const double a = 2.0 * core::kPi * c / k;
    core::Camera cam;
    cam.name = "ring" + std::to_string(c);
    cam.width = 640;
    cam.height = 480;
    cam.intrinsics = core::intrinsicsFromFov(core::deg2rad(60.0), 640, 480);
    cam.c_M_w = core::lookAt({6.0 * std::cos(a), 6.0 * std::sin(a), 1.5}, {0.0, 0.0, 2.8}, {0.0, 0.0, 1.0});
    cams.push_back(cam);
  }
  return cams;
}

ScalingPoint scalingPoint(int k, double seconds, std::uint64_t seed) {
  const auto cams = ringCameras(k);
  tracking::TrackerConfig cfg;
  tracking::ViewlineTracker tracker(cams, cfg);
  core::Rng rng = core::makeRng(seed);
  const Eigen::Vector3d p0(0.0, 0.0, 2.0), v0(0.5, 0.3, 5.0), g(0.0, 0.0, -9.81);
  const double period = 0.01;  // 100 Hz
  // Measurements in capture-time order: camera c at t = j period + c period / k.
  std::vector<tracking::ImageMeasurement> ms;
  const int steps = static_cast<int>(std::round(seconds / period));
  std::uint64_t id = 1;
  for (int j = 0; j < steps; ++j) {
    for (int c = 0; c < k; ++c) {
      const double t = j * period + c * period / k;
      const double tf = std::fmod(t, 1.0);  // a new throw every second
      const Eigen::Vector3d p = p0 + v0 * tf + 0.5 * g * tf * tf;
      const auto uv = cams[static_cast<std::size_t>(c)].project(p);
      if (!uv) continue;
      const Eigen::Vector2d px = *uv + 0.5 * Eigen::Vector2d(core::gaussian(rng), core::gaussian(rng));
      ms.push_back({id++, static_cast<std::size_t>(c), t, px, 0.5});
    }
  }
  ScalingPoint pt;
  pt.cameras = k;
  const double c0 = latency::threadCpuNow();
  for (const auto& m : ms) {
    pt.fused += tracker.submit(m) == tracking::Refusal::None && tracker.lastUpdate() &&
                tracker.lastUpdate()->decision != tracking::GateDecision::Reject;
  }
  pt.core_fraction = (latency::threadCpuNow() - c0) / seconds;
  pt.submitted = ms.size();
  return pt;
}

void printStats(const char* what, const latency::Stats& s) {
  std::printf("| %s | %zu | %.1f | %.1f | %.1f |\n", what, s.n, 1e6 * s.median, 1e6 * s.p99, 1e6 * s.mean);
}

// The pan-tilt rows of the report.
PanTiltFigures panTiltRows(double record_seconds, std::size_t frames) {
  std::size_t recorded = 0;
  const PanTiltFigures f =
      panTilt(std::string(VIEWLINE_SOURCE_DIR) + "/config/pan_tilt_rectangle.yaml", record_seconds, frames, recorded);
  std::printf("\n## Pan-tilt, 640x480, detection + back-projection + target filter + control law (%zu recorded frames replayed)\n\n",
              recorded);
  std::printf("| sample | frames | median (us) | p99 (us) | mean (us) |\n|---|---|---|---|---|\n");
  printStats("every frame", f.total);
  printStats("  of which detection + back-projection", f.detect);
  printStats("  of which target filter (observe)", f.filter);
  printStats("  of which control law (command)", f.law);
  std::printf("\nDetector: %zu of %zu timed frames answered from the window around the last detection.\n", f.windowed,
              f.total.n);
  return f;
}

// The table-ball rows of the report (with `stages`, the fast path's stage breakdown too).
TableBallFigures tableBallRows(double record_seconds, std::size_t frames, bool stages) {
  std::size_t recorded = 0;
  const TableBallFigures f =
      tableBall(std::string(VIEWLINE_SOURCE_DIR) + "/config/table_ball.yaml", record_seconds, frames, recorded, stages);
  std::printf("\n## Table ball, 320x240, observer (table + ball detection, filter) + controller (%zu recorded frames replayed)\n\n",
              recorded);
  std::printf("| sample | frames | median (us) | p99 (us) | mean (us) |\n|---|---|---|---|---|\n");
  printStats("every frame", f.total);
  printStats("  fast path (sides and ball tracked locally)", f.tracked);
  if (stages) {
    printStats("    of which edge tracking (four sides)", f.fast_edges);
    printStats("    of which ball window", f.fast_ball);
    printStats("    of which PnP refine (border-aware)", f.fast_pose);
    printStats("    of which pose filter, tilt, ball on the table", f.fast_geometry);
    printStats("    of which rolling-ball filter", f.fast_filter);
    printStats("    of which controller", f.fast_control);
  }
  printStats("  full detection ([M]'s pipeline)", f.detected);
  return f;
}

}  // namespace

int main(int argc, char** argv) {
  cv::setNumThreads(1);
  std::size_t frames = 10000;
  double scaling_seconds = 2.0, record_seconds = 6.0;
  int throws = 2;
  bool check = false, pan_tilt_only = false, table_ball_only = false, stages = false;
  std::string config = std::string(VIEWLINE_SOURCE_DIR) + "/config/ball_catching.yaml";
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (i + 1 < argc && a == "--frames") frames = static_cast<std::size_t>(std::atol(argv[++i]));
    else if (i + 1 < argc && a == "--scaling-seconds") scaling_seconds = std::atof(argv[++i]);
    else if (i + 1 < argc && a == "--config") config = argv[++i];
    else if (i + 1 < argc && a == "--throws") throws = std::atoi(argv[++i]);
    else if (i + 1 < argc && a == "--record-seconds") record_seconds = std::atof(argv[++i]);
    else if (a == "--check") check = true;
    else if (a == "--pan-tilt-only") pan_tilt_only = true;
    else if (a == "--table-ball-only") table_ball_only = true;
    else if (a == "--stages") stages = true;
    else {
      std::fprintf(stderr,
                   "usage: %s [--frames N>=1] [--scaling-seconds S>0] [--throws N>=1] [--record-seconds S>=1] "
                   "[--config FILE] [--check] [--pan-tilt-only] [--table-ball-only] [--stages]\n",
                   argv[0]);
      return 2;
    }
  }
  if (frames < 1 || !(scaling_seconds > 0.0) || throws < 1 || !(record_seconds >= 1.0)) {
    std::fprintf(stderr, "%s: --frames and --throws must be >= 1, --scaling-seconds > 0, --record-seconds >= 1\n", argv[0]);
    return 2;
  }
  try {
    std::printf("# Per-frame processing (thread CPU time, one core); load %s\n\n", latency::loadAverage().c_str());
    if (pan_tilt_only) {
      panTiltRows(record_seconds, frames);
      return 0;
    }
    if (table_ball_only) {
      tableBallRows(record_seconds, frames, stages);
      return 0;
    }
    const CatchFigures bc = ballCatching(config, throws, frames);
    std::printf("## Ball catching, 656x480, detect + track + plan (%zu recorded frames replayed)\n\n", bc.recorded);
    std::printf("| sample | frames | median (us) | p99 (us) | mean (us) |\n|---|---|---|---|---|\n");
    printStats("tracking: ball found in the window", bc.window);
    printStats("  of which detection (prediction + detector)", bc.detect_window);
    printStats("  of which tracker (submit + outcome)", bc.track_window);
    printStats("  of which planner (update + set point)", bc.plan_window);
    printStats("tracking: full-frame searches", bc.full_in_tracking);
    printStats("acquisition: every frame searched whole", bc.acquisition);

    const latency::Stats tb = tableBallRows(record_seconds, frames, stages).total;

    const PanTiltFigures pt_frames = panTiltRows(record_seconds, frames);

    std::printf("\n## Scaling: K cameras at 100 Hz into one tracker (%.1f s of data each)\n\n", scaling_seconds);
    std::printf("| cameras | images | fused | share of one core (%%) |\n|---|---|---|---|\n");
    std::vector<ScalingPoint> pts;
    for (int k : {1, 2, 4, 8, 16, 32, 64}) {
      pts.push_back(scalingPoint(k, scaling_seconds, 100 + static_cast<std::uint64_t>(k)));
      std::printf("| %d | %zu | %zu | %.3f |\n", k, pts.back().submitted, pts.back().fused, 100.0 * pts.back().core_fraction);
    }
    // Least squares core_fraction = a + b K.
    Eigen::MatrixXd A(static_cast<Eigen::Index>(pts.size()), 2);
    Eigen::VectorXd y(static_cast<Eigen::Index>(pts.size()));
    for (std::size_t i = 0; i < pts.size(); ++i) {
      A(static_cast<Eigen::Index>(i), 0) = 1.0;
      A(static_cast<Eigen::Index>(i), 1) = pts[i].cameras;
      y[static_cast<Eigen::Index>(i)] = pts[i].core_fraction;
    }
    const Eigen::Vector2d ab = A.colPivHouseholderQr().solve(y);
    const Eigen::VectorXd res = y - A * ab;
    const double rms = std::sqrt(res.squaredNorm() / static_cast<double>(pts.size()));
    std::printf("\nfit: share = %.4f %% + %.4f %% per camera; residual RMS %.4f %% (max %.4f %%); 64 cameras: %.2f %% "
                "(target <= 10 %%)\n",
                100.0 * ab[0], 100.0 * ab[1], 100.0 * rms, 100.0 * res.cwiseAbs().maxCoeff(),
                100.0 * pts.back().core_fraction);

    if (!check) return 0;
    const std::vector<Budget> budgets{
        {"ball catching, tracking (window) p99", 0.5e-3, bc.window.p99},
        {"ball catching, acquisition (full frame) p99", 1.5e-3, bc.acquisition.p99},
        {"table ball, per frame p99", 0.3e-3, tb.p99},
        {"pan-tilt, per frame p99 (with the target filter)", 0.5e-3, pt_frames.total.p99},
        {"64 cameras at 100 Hz, share of one core", 0.10, pts.back().core_fraction},
    };
    std::printf("\n## Budget check (fails above 1.2 x budget)\n\n| figure | budget | measured | ratio | verdict |\n|---|---|---|---|---|\n");
    bool ok = true;
    for (const auto& b : budgets) {
      const double r = b.measured_s / b.budget_s;
      const bool pass = r <= 1.2;
      ok = ok && pass;
      std::printf("| %s | %.4g | %.4g | %.2f | %s |\n", b.what, b.budget_s, b.measured_s, r, pass ? "ok" : "OVER");
    }
    std::printf("\nbudget check: %s\n", ok ? "passed" : "FAILED");
    return ok ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: %s\n", argv[0], e.what());
    return 1;
  }
}
