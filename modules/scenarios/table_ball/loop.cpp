#include "viewline/scenarios/table_ball/loop.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <functional>
#include <limits>
#include <optional>

#include "viewline/control/table_balancer.h"
#include "viewline/core/error.h"
#include "viewline/runtime/delay_line.h"
#include "viewline/runtime/recording.h"
#include "viewline/runtime/stale_frames.h"
#include "viewline/scenarios/table_ball/world.h"
#include "viewline/scenarios/table_ball/wrist_link.h"
#include "viewline/vision/table_detector.h"

namespace viewline::scenarios {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kTick = TableBallWorld::kTick;

/// CPU time of the calling thread, s (the observer and the reference run on it, one after the
/// other; unlike wall time it does not count the time the thread waits for a core).
double threadCpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

Eigen::Vector2d positionOf(const Eigen::VectorXd& x) { return {x[0], x[2]}; }
Eigen::Vector2d velocityOf(const Eigen::VectorXd& x) { return {x[1], x[3]}; }

/// [M]'s plain steps (vision::referenceTableScene: full frame, fresh buffers, no refinements)
/// and the same filter, run on the same frames for the cost ratio.
class ReferencePipeline {
public:
  ReferencePipeline(const core::Camera& camera, const TableBallObserverConfig& ocfg)
      : camera_(camera), gravity_w_(ocfg.gravity_w), detector_(ocfg.detector), tracker_(ocfg.tracker) {
    detector_.refine = false;
  }
  /// Wall-clock seconds of one frame. `a_fallback`: the input when the table is not found.
  double run(const cv::Mat& image, double t, const Eigen::Matrix3d& c_R_w, const Eigen::Isometry3d& c_M_t_nominal,
             const Eigen::Vector2d& a_fallback) {
    const auto r0 = std::chrono::steady_clock::now();
    const vision::TableScene rs = vision::referenceTableScene(image, t, camera_, detector_, c_M_t_nominal);
    std::optional<Eigen::Vector2d> ry;
    Eigen::Vector2d ra = a_fallback;
    if (rs.table) {
      ra = estimation::rollingBallAcceleration(estimation::tableRotationInWorld(rs.table->c_M_t.linear(), c_R_w),
                                               gravity_w_);
      if (rs.ball) ry = rs.ball->known_radius.p_t.head<2>();
    }
    if (tracker_.initialized() || ry) tracker_.step(t, ra, ry);
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - r0).count();
  }

private:
  core::Camera camera_;
  Eigen::Vector3d gravity_w_;
  vision::TableDetectorConfig detector_;
  tracking::RollingBallTracker tracker_;
};

SideFilters makeSideFilters(const TableBallConfig& cfg, const tracking::RollingBallTrackerConfig& tracker) {
  SideFilters side;
  if (!cfg.compare_tunings) return side;
  tracking::RollingBallTrackerConfig a = tracker, b = tracker, st = tracker;
  a.model.sigma_w = 1.0;
  a.model.sigma_v = 0.005;
  a.stationary_gain = false;
  a.impulse_nis = 0.0;  // [M]'s filters: no push model, white measurement noise
  a.coloured_sigma = 0.0;
  b.model.sigma_w = 1.0;
  b.model.sigma_v = 1.0;
  b.stationary_gain = false;
  b.impulse_nis = 0.0;
  b.coloured_sigma = 0.0;
  st.stationary_gain = true;
  st.coloured_sigma = 0.0;  // the DARE gain of the white-noise model
  side.emplace_back("M_best", tracking::RollingBallTracker(a));
  side.emplace_back("M_lag", tracking::RollingBallTracker(b));
  side.emplace_back("stationary", tracking::RollingBallTracker(st));
  return side;
}

Eigen::VectorXd vec(std::initializer_list<double> v) {
  Eigen::VectorXd x(static_cast<Eigen::Index>(v.size()));
  Eigen::Index i = 0;
  for (double e : v) x[i++] = e;
  return x;
}

/// The records of one frame (see TableBallHooks::telemetry).
void reportFrame(runtime::TelemetrySink& sink, double t, double capture_time, const sim::TiltTableState& truth,
                 const Eigen::Vector2d& ref, const ObserverFrame& of, const tracking::RollingBallTracker& tracker,
                 const SideFilters& side, double sigma_v) {
  if (of.table_found) sink.measurement({"table_tilt", t, 0, of.measured_tilt, {}});
  if (of.ball_found) sink.measurement({"ball", t, 0, of.measured, Eigen::Vector2d::Constant(sigma_v)});
  sink.measurement({"ball_acceleration", t, 0, of.a_xy, {}});
  if (const auto& u = tracker.lastUpdate()) {
    sink.innovation({"ball", t, 0, 0, u->report.rows, u->report.innovation, u->report.S, u->report.nis, u->decision});
  }
  if (of.estimate_valid) {
    sink.estimate({"ball", t, of.x, tracker.P()});
    if (!of.predictions.empty()) sink.estimate({"ball_prediction", t, of.predictions.back(), {}});
  }
  for (const auto& [name, trk] : side) {
    if (trk.initialized()) sink.estimate({"ball_" + name, t, trk.x(), trk.P()});
  }
  sink.estimate({"truth", capture_time, vec({truth.p.x(), truth.p.y(), truth.v.x(), truth.v.y(), truth.tilt.x(),
                                             truth.tilt.y()}), {}});
  sink.command({"setpoint", t, ref});
}

}  // namespace

TableBallResult runTableBall(const TableBallConfig& cfg, std::uint64_t seed, const TableBallHooks& hooks) {
  if (cfg.onFootage() && hooks.replay_dir.empty())
    throw core::InvalidInput(std::string("source.kind ") + runtime::toString(cfg.source.kind) +
                             ": footage runs as one session without truth (runTableBallFootage)");
  const auto wall0 = std::chrono::steady_clock::now();
  const double period = cfg.framePeriod();
  TableBallWorld world(cfg, seed);
  // The frame source: the rendered head camera, or a recording of a simulated run (config.source or
  // hooks.replay_dir). The table, its physics and the truth stay simulated either way.
  RenderedHeadCamera renderer(world, cfg.exposure, cfg.duration);
  std::unique_ptr<runtime::RecordingSource> recorded;
  if (!hooks.replay_dir.empty())
    recorded = std::make_unique<runtime::RecordingSource>(hooks.replay_dir);
  else if (cfg.source.kind == runtime::SourceKind::Recording)
    recorded = std::make_unique<runtime::RecordingSource>(cfg.source.recording);
  runtime::FaultPlan faults(cfg.faults, core::deriveSeed(seed, 0xFA));
  runtime::StaleFrameFilter stale;
  runtime::FrameSource& camera = faults.wrap(recorded ? static_cast<runtime::FrameSource&>(*recorded) : renderer);
  std::unique_ptr<runtime::RecordingWriter> writer;
  if (!hooks.record_dir.empty()) {
    writer = std::make_unique<runtime::RecordingWriter>(hooks.record_dir);
    writer->setCamera(0, world.observerCamera());  // the calibration the observer uses
    if (!hooks.config_text.empty()) writer->setConfig(hooks.config_text);
  }
  const core::Camera& obs_camera = world.observerCamera();
  const TableBallObserverConfig ocfg = world.observerConfig();
  TableBallObserver observer(obs_camera, ocfg);
  SideFilters side = makeSideFilters(cfg, ocfg.tracker);
  ReferencePipeline reference(obs_camera, ocfg);
  control::TableBalancer controller(cfg.controllerConfig(world.wrist()));
  TableBallMetrics metrics(cfg);
  runtime::TelemetrySink* sink = hooks.telemetry;

  runtime::Scheduler sched;
  sched.setPacing(hooks.pacing);
  // The arm's trajectory interpolator: it starts a ramp at the first tick at or after the ramp's
  // start (capture + latency) and holds the newest plan (a newer ramp replaces one not started).
  runtime::DelayLine<control::TiltRamp> to_arm;
  control::TiltRamp current;  // holds the level table until the first estimate
  current.t0 = -1.0;
  current.period = period;
  bool frame_pending = false;
  // The wrist behind the fault plan (wrist_link.h). wrist_failed: a command failed since the
  // controller last heard of it (the controller's model must then take the held tilt).
  WristLink wrist(world.wrist(), faults);
  bool wrist_failed = false;
  double last_stamp = -std::numeric_limits<double>::infinity();  // of the last frame the loop used

  // --- physics: tick k at k · kTick (scheduled from k, not accumulated) -----------------------
  std::function<void(double)> tick = [&](double) {
    const double t = world.time();
    // Past the last frame and the duration: stop ticking.
    if (!frame_pending && t >= cfg.duration - table_ball_order::kTimeTolerance) return;
    to_arm.receive(t, [&](double, const control::TiltRamp& r) { current = r; });
    if (!wrist.send(t, current.commandAt(t))) {
      // Not taken: the wrist holds its set point, and so does the loop's command (the ramps
      // planned before the failure assumed it would move; none of them is sent).
      current = control::TiltRamp{};
      current.t0 = t;
      current.start = wrist.held();
      current.period = period;
      to_arm.clear();
      wrist_failed = true;
    }
    const Eigen::Vector2d cmd = wrist.lastCommand();
    metrics.command(cmd);
    world.step();
    metrics.tick(world.time(), world.state().p);
    if (sink != nullptr && world.ticks() % 5 == 0) sink->command({"wrist", t, cmd});
    sched.at(world.time(), table_ball_order::kTick, tick);
  };

  // --- frames ----------------------------------------------------------------------------------
  core::Camera view_camera = obs_camera;
  double next_progress = 0.0;
  bool stopped = false;
  std::function<void(double)> on_frame;
  auto scheduleFrame = [&] {
    const std::optional<double> ready = camera.nextReadyTime();
    frame_pending = ready.has_value();
    if (ready)
      sched.at(std::max(sched.now(), *ready - table_ball_order::kTimeTolerance), table_ball_order::kFrame, on_frame);
  };
  on_frame = [&](double) {
    const double ready = camera.nextReadyTime().value_or(sched.now());
    std::optional<runtime::Frame> frame = camera.grab();
    sim::Capture cap;  // the grab's times, known for a lost frame too (the driver's sequence gap)
    if (recorded) {
      const runtime::RecordingEntry* e = recorded->lastEntry();
      if (e == nullptr || !std::isfinite(e->stamp) || !std::isfinite(e->capture_time))
        throw core::InvalidInput("recording " + recorded->dir() + ": a lost frame without its times");
      cap.capture_time = e->capture_time;
      cap.stamp = e->stamp;
    } else {
      cap = renderer.lastCapture();
    }
    if (writer) {
      runtime::Frame meta;
      meta.capture_time = cap.capture_time;
      meta.stamp = cap.stamp;
      meta.sequence = frame ? frame->sequence : cap.sequence;
      if (frame)
        writer->frame(ready, *frame);
      else
        writer->lost(ready, meta);
    }
    if (frame && faults.missesDeadline(*frame)) {  // stale: dropped as a lost frame (faults.h)
      faults.note("frames_late_dropped");
      frame.reset();
    }
    if (frame && stale.repeats(*frame)) {  // a frozen camera's old image with a new stamp (stale_frames.h)
      faults.note("frames_frozen_dropped");
      frame.reset();
    }
    const double t = frame ? frame->stamp : cap.stamp;  // the stamp as delivered (injected stamp faults)
    if (!(t > last_stamp)) {  // a repeated or backward stamp: the filters only step forward in time
      faults.note("frames_stale_stamp_dropped");
      scheduleFrame();
      return;
    }
    last_stamp = t;
    const sim::TiltTableState truth = world.stateAt(cap.capture_time);
    const Eigen::Vector2d ref = cfg.setpointAt(t);
    if (wrist_failed) {
      // The wrist did not take the ramps since its last accepted set point: the controller's
      // tilt model (and the nominal table pose below) take the tilt it holds; while it does not
      // answer the controller is not stepped, so its integral does not grow.
      controller.hold(wrist.held());
      wrist_failed = wrist.down();
    }
    const Eigen::Isometry3d w_M_t_nominal = world.tablePose(controller.modelTilt());

    const ObserverFrame* of = nullptr;
    if (frame) {
      const Eigen::Isometry3d obs_c_M_w = world.observerHeadPose(cap.capture_time);
      view_camera.c_M_w = obs_c_M_w;
      const Eigen::Matrix3d c_R_w = world.groundRotationReading(obs_c_M_w);
      const Eigen::Isometry3d c_M_t_nominal = obs_c_M_w * w_M_t_nominal;
      const double c0 = threadCpuSeconds();
      const auto processed = runtime::guardedDetect(faults, frame->camera, cap.capture_time, [&] {
        return &observer.process(frame->image, t, c_R_w, c_M_t_nominal);
      });
      of = processed ? *processed : &observer.predictOnly(t);
      const double c1 = threadCpuSeconds();
      if (cfg.time_reference) {
        const double ref_wall = reference.run(frame->image, t, c_R_w, c_M_t_nominal, of->a_xy);
        metrics.timing(of->seconds, ref_wall, c1 - c0, threadCpuSeconds() - c1);
      }
    } else {
      of = &observer.predictOnly(t);
    }
    const std::optional<Eigen::Vector2d> y = of->ball_found ? std::optional<Eigen::Vector2d>(of->measured) : std::nullopt;
    for (auto& [name, trk] : side) {
      if (trk.initialized() || y) trk.step(t, of->a_xy, y);
    }
    metrics.frame(t, truth, *of, observer.tracker(), side);

    if (of->estimate_valid && !wrist.down()) {
      control::TiltRamp ramp = controller.update(t, positionOf(of->x), velocityOf(of->x), ref);
      ramp.t0 = cap.capture_time + cfg.latency;
      to_arm.clear();
      to_arm.send(ramp.t0 - table_ball_order::kTimeTolerance, ramp);
      if (sink != nullptr) sink->command({"tilt_ramp", ramp.t0, vec({ramp.start.x(), ramp.start.y(), ramp.rate.x(), ramp.rate.y()})});
    }
    if (sink != nullptr) {
      reportFrame(*sink, t, cap.capture_time, truth, ref, *of, observer.tracker(), side, ocfg.tracker.model.sigma_v);
    }
    if (hooks.on_frame) {
      TableBallFrameView view;
      view.image = frame ? &frame->image : nullptr;
      view.camera = &view_camera;  // the observer's camera (calibrated with a rig) at the last frame
      view.observer = of;
      view.truth = truth.p;
      view.setpoint = ref;
      view.tilt = truth.tilt;
      const auto shown = std::chrono::steady_clock::now();
      if (!hooks.on_frame(view)) {
        stopped = true;
        sched.requestStop();
      }
      // A viewer that held the run (pause, single steps) must not make the paced run sprint to
      // catch up afterwards: the pacing restarts from here.
      if (hooks.pacing.paced() && std::chrono::steady_clock::now() - shown > std::chrono::milliseconds(250)) {
        sched.setPacing(hooks.pacing);
      }
    }
    if (hooks.on_progress && t >= next_progress) {
      hooks.on_progress(t, cfg.duration);
      next_progress += 1.0;
    }
    scheduleFrame();
  };

  scheduleFrame();
  sched.at(world.time(), table_ball_order::kTick, tick);
  sched.runUntil(std::numeric_limits<double>::infinity());

  if (writer) writer->finish();
  TableBallResult res = metrics.result(seed);
  res.stopped_early = stopped;
  if (!faults.empty()) res.faults = faults.report();
  if (sink != nullptr) sink->flush();
  res.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  return res;
}

}  // namespace viewline::scenarios
