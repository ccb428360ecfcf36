#include "viewline/scenarios/table_ball/footage.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>

#include "viewline/control/table_balancer.h"
#include "viewline/core/error.h"
#include "viewline/core/frames.h"
#include "viewline/robots/table_tilt.h"
#include "viewline/runtime/delay_line.h"
#include "viewline/runtime/merged_source.h"
#include "viewline/runtime/recording.h"
#include "viewline/runtime/scheduler.h"
#include "viewline/runtime/source_config.h"
#include "viewline/runtime/stale_frames.h"
#include "viewline/scenarios/table_ball/world.h"
#include "viewline/scenarios/table_ball/wrist_link.h"

namespace viewline::scenarios {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kTick = TableBallWorld::kTick;

}  // namespace

std::string tableBallFootageName(const runtime::SourceConfig& s) { return runtime::describeSource(s); }

namespace {

/// The hooks a session over recorded frames cannot honour (footage.h), refused.
void refuseRecordReplayPacing(const TableBallHooks& hooks) {
  if (!hooks.record_dir.empty())
    throw core::InvalidInput("--record: footage is recorded already (a recording holds a simulated run)");
  if (!hooks.replay_dir.empty()) throw core::InvalidInput("--replay: the footage is the input (source:)");
  if (hooks.pacing.paced()) throw core::InvalidInput("--realtime: footage is paced by its source (source.pace: true)");
}

/// The session (footage.h) over footage already opened; `source_name` names it in the summary.
TableBallFootageSummary runOnFootage(const TableBallConfig& cfg, std::uint64_t seed, const TableBallHooks& hooks,
                                     runtime::WallClock* clock, runtime::SingleCameraFootage opened,
                                     const std::string& source_name) {
  const auto wall0 = std::chrono::steady_clock::now();
  TableBallFootageSummary sum;
  sum.seed = seed;
  sum.source = source_name;
  const std::unique_ptr<runtime::FrameSource>& footage = opened.source;
  const double t0 = opened.t0;
  runtime::LiveFrameSource* const live = opened.live;

  // The world gives what the design fixes: the observer's camera (the rig's calibration or the
  // inline camera) and configuration, and the arm's kinematics. Nothing in it is rendered.
  TableBallWorld world(cfg, seed);
  const core::Camera& obs_camera = world.observerCamera();
  // The head at its calibrated rest pose: footage carries no measurement of its sway.
  const Eigen::Isometry3d c_M_w = obs_camera.c_M_w;
  TableBallObserverConfig ocfg = world.observerConfig();
  // The pose filter's kinematic pose would be the simulated wrist's table, not the footage's
  // (footage.h): each frame's own PnP pose.
  ocfg.table_pose_time_constant = 0.0;
  TableBallObserver observer(obs_camera, ocfg);

  runtime::FaultPlan faults(cfg.faults, core::deriveSeed(seed, 0xFA));
  runtime::FrameSource& camera = faults.wrap(*footage);
  runtime::StaleFrameFilter stale;
  // The simulated wrist on the footage's clock, commanded from its first frame.
  robots::SimulatedTableTilt wrist_sim(cfg.wrist, Eigen::Vector2d::Zero(), t0);
  WristLink wrist(wrist_sim, faults);
  bool wrist_failed = false;
  Eigen::Vector2d wrist_tilt = Eigen::Vector2d::Zero();  // the wrist's actual tilt at the last tick
  control::TableBalancer controller(cfg.controllerConfig(wrist_sim));
  runtime::DelayLine<control::TiltRamp> to_arm;
  control::TiltRamp current;  // holds the level table until the first estimate
  current.t0 = t0 - 1.0;
  current.period = cfg.framePeriod();
  runtime::TelemetrySink* sink = hooks.telemetry;

  std::optional<runtime::ProcessingTimer> timer;
  char origin[96];
  std::snprintf(origin, sizeof origin, "one frame period at %.4g fps (camera.rate_hz)", cfg.rate_hz);
  if (live) timer.emplace(cfg.framePeriod(), clock);

  runtime::Scheduler sched(t0);
  bool source_done = false;
  double t_end = std::numeric_limits<double>::infinity();  // the last ramp has reached the wrist
  bool have_cmd = false;
  Eigen::Vector2d last_cmd = Eigen::Vector2d::Zero();
  long k = 0;  // tick k at t0 + k · kTick (from k, not accumulated)

  // --- the wrist: one position command per tick, through the fault plan -----------------------
  std::function<void(double)> tick = [&](double) {
    const double t = t0 + static_cast<double>(k) * kTick;
    if (source_done && t >= t_end) return;
    to_arm.receive(t, [&](double, const control::TiltRamp& r) { current = r; });
    if (!wrist.send(t, current.commandAt(t))) {
      // As in the loop: the wrist holds its set point, and so does the command.
      current = control::TiltRamp{};
      current.t0 = t;
      current.start = wrist.held();
      current.period = cfg.framePeriod();
      to_arm.clear();
      wrist_failed = true;
    }
    const Eigen::Vector2d cmd = wrist.lastCommand();
    // The same check as the simulated run's (TableBallMetrics::command).
    bool ok = cfg.wrist.withinAngle(cmd, 1e-12);
    if (have_cmd) {
      const double rate = (cmd - last_cmd).cwiseAbs().maxCoeff() / kTick;
      sum.max_commanded_rate_deg_s = std::max(sum.max_commanded_rate_deg_s, core::rad2deg(rate));
      if (rate > cfg.wrist.max_rate * (1.0 + 1e-9) + 1e-12) ok = false;
    }
    if (!ok) ++sum.limit_violations;
    sum.max_commanded_angle_deg = std::max(sum.max_commanded_angle_deg, core::rad2deg(cmd.cwiseAbs().maxCoeff()));
    last_cmd = cmd;
    have_cmd = true;
    ++sum.wrist_commands;
    wrist_tilt = wrist_sim.actual(t);
    if (sink != nullptr && k % 5 == 0) sink->command({"wrist", t, cmd});
    ++k;
    sched.at(t0 + static_cast<double>(k) * kTick, table_ball_order::kTick, tick);
  };

  // --- frames ----------------------------------------------------------------------------------
  core::Camera view_camera = obs_camera;
  view_camera.c_M_w = c_M_w;
  double last_stamp = -std::numeric_limits<double>::infinity();
  double next_progress = 0.0, nis_sum = 0.0;
  std::uint64_t grabs = 0;
  std::function<void(double)> on_frame;
  auto scheduleFrame = [&] {
    const std::optional<double> ready = camera.nextReadyTime();
    if (!ready) {
      // The ramp of the last frame still starts (latency) and reaches the wrist (its delay).
      source_done = true;
      t_end = sched.now() + cfg.latency + cfg.wrist.delay + kTick;
      return;
    }
    sched.at(std::max(sched.now(), *ready - table_ball_order::kTimeTolerance), table_ball_order::kFrame, on_frame);
  };
  on_frame = [&](double) {
    std::optional<runtime::Frame> frame = camera.grab();
    if (!frame) {  // lost: no stamp to predict to (a file's lost frame is simply absent)
      ++sum.lost;
      scheduleFrame();
      return;
    }
    const std::uint64_t id = ++grabs;
    if (timer) timer->resume(id);
    ++sum.frames;
    if (frame->image.type() != CV_8UC3)
      throw core::InvalidInput("source: " + sum.source + ": frame " + std::to_string(frame->sequence) +
                               " is not a colour (8-bit BGR) image: the table and the ball are found by colour");
    if (static_cast<unsigned>(frame->image.cols) != obs_camera.width ||
        static_cast<unsigned>(frame->image.rows) != obs_camera.height)
      throw core::InvalidInput("source: " + sum.source + ": frame " + std::to_string(frame->sequence) + " is " +
                               std::to_string(frame->image.cols) + "x" + std::to_string(frame->image.rows) +
                               " px, the head camera's calibration is " + std::to_string(obs_camera.width) + "x" +
                               std::to_string(obs_camera.height) + " px");
    const double t = frame->stamp;
    if (sum.frames == 1) sum.t_first = sum.t_last = t;
    sum.t_last = std::max(sum.t_last, t);
    if (faults.missesDeadline(*frame)) {  // as in the loop: dropped as a lost frame
      faults.note("frames_late_dropped");
      frame.reset();
    }
    if (frame && stale.repeats(*frame)) {
      faults.note("frames_frozen_dropped");
      frame.reset();
    }
    if (!(t > last_stamp)) {  // the filters only step forward in time
      faults.note("frames_stale_stamp_dropped");
      ++sum.skipped;
      if (timer) timer->finish(id);
      scheduleFrame();
      return;
    }
    last_stamp = t;
    if (!frame) ++sum.skipped;
    if (wrist_failed) {
      controller.hold(wrist.held());
      wrist_failed = wrist.down();
    }
    // The quarter-turn prior: the table as the simulated wrist holds it, seen from the rest pose.
    const Eigen::Isometry3d c_M_t_nominal = c_M_w * world.tablePose(wrist_tilt);
    const ObserverFrame* of = nullptr;
    if (frame) {
      const auto processed = runtime::guardedDetect(faults, frame->camera, t, [&] {
        return &observer.process(frame->image, t, c_M_w.linear(), c_M_t_nominal);
      });
      of = processed ? *processed : &observer.predictOnly(t);
    } else {
      of = &observer.predictOnly(t);
    }
    if (of->image) {  // a prediction-only step keeps the last image's flags
      if (of->table_found) ++sum.table_found;
      if (of->ball_found) ++sum.ball_found;
      if (of->tracked) ++sum.tracked;
    }
    if (of->ball_found && observer.tracker().initialized() && t - t0 >= cfg.warmup) {
      nis_sum += observer.tracker().lastNis();
      ++sum.nis_count;
    }
    const Eigen::Vector2d ref = cfg.setpointAt(t - t0);
    if (of->estimate_valid && !wrist.down()) {
      control::TiltRamp ramp = controller.update(t, {of->x[0], of->x[2]}, {of->x[1], of->x[3]}, ref);
      ramp.t0 = t + cfg.latency;
      to_arm.clear();
      to_arm.send(ramp.t0 - table_ball_order::kTimeTolerance, ramp);
      ++sum.ramps;
      if (sink != nullptr) {
        Eigen::VectorXd u(4);
        u << ramp.start.x(), ramp.start.y(), ramp.rate.x(), ramp.rate.y();
        sink->command({"tilt_ramp", ramp.t0, u});
      }
    }
    if (timer) timer->finish(id);
    if (sink != nullptr) {
      if (of->table_found) sink->measurement({"table_tilt", t, 0, of->measured_tilt, {}});
      if (of->ball_found)
        sink->measurement({"ball", t, 0, of->measured, Eigen::Vector2d::Constant(ocfg.tracker.model.sigma_v)});
      sink->measurement({"ball_acceleration", t, 0, of->a_xy, {}});
      if (const auto& u = observer.tracker().lastUpdate())
        sink->innovation({"ball", t, 0, 0, u->report.rows, u->report.innovation, u->report.S, u->report.nis, u->decision});
      if (of->estimate_valid) sink->estimate({"ball", t, of->x, observer.tracker().P()});
      sink->command({"setpoint", t, ref});
    }
    if (hooks.on_frame) {
      TableBallFrameView view;
      view.image = frame ? &frame->image : nullptr;
      view.camera = &view_camera;
      view.observer = of;
      view.truth = Eigen::Vector2d::Constant(kNaN);  // no truth behind footage
      view.setpoint = ref;
      view.tilt = wrist_tilt;
      if (!hooks.on_frame(view)) sched.requestStop();
    }
    if (hooks.on_progress && t - t0 >= next_progress) {
      hooks.on_progress(t - t0, kNaN);
      next_progress += 1.0;
    }
    scheduleFrame();
  };

  scheduleFrame();
  sched.at(t0, table_ball_order::kTick, tick);
  sched.runUntil(std::numeric_limits<double>::infinity());

  sum.stopped_early = sched.stopRequested();
  sum.nis_mean = sum.nis_count > 0 ? nis_sum / static_cast<double>(sum.nis_count) : kNaN;
  if (timer && live) sum.live = runtime::liveReport(*live, *timer, origin);
  if (!faults.empty()) sum.faults = faults.report();
  if (sink != nullptr) sink->flush();
  sum.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  return sum;
}

}  // namespace

TableBallFootageSummary runTableBallFootage(const TableBallConfig& cfg, std::uint64_t seed, const TableBallHooks& hooks,
                                            runtime::WallClock* clock) {
  cfg.validate();
  if (!cfg.onFootage())
    throw core::InvalidInput(std::string("source.kind: expected footage (images, video or v4l2), got ") +
                             runtime::toString(cfg.source.kind));
  refuseRecordReplayPacing(hooks);
  const std::string name = tableBallFootageName(cfg.source);
  return runOnFootage(cfg, seed, hooks, clock, runtime::openSingleCameraFootage(cfg.source, clock, "the head camera"), name);
}

TableBallFootageSummary runTableBallOnRecording(const TableBallConfig& cfg, std::uint64_t seed, const std::string& dir,
                                                const TableBallHooks& hooks) {
  cfg.validate();
  refuseRecordReplayPacing(hooks);
  runtime::SingleCameraFootage opened;
  auto recording = std::make_unique<runtime::RecordingSource>(dir);
  if (recording->cameraCount() != 1)
    throw core::InvalidInput(dir + ": a recording of " + std::to_string(recording->cameraCount()) +
                             " cameras (table_ball has one, the head camera)");
  const std::optional<double> first = recording->nextReadyTime();
  if (!first) throw core::InvalidInput(dir + ": the recording holds no frame");
  opened.t0 = *first;
  opened.source = std::move(recording);
  return runOnFootage(cfg, seed, hooks, nullptr, std::move(opened), "recording " + dir);
}

namespace {

nlohmann::json num(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

}  // namespace

nlohmann::json toJson(const TableBallFootageSummary& s) {
  nlohmann::json j = {
      {"mode", "footage"},
      {"seed", s.seed},
      {"source", s.source},
      {"footage_s", {{"first_stamp", s.t_first}, {"last_stamp", s.t_last}}},
      {"frames", s.frames},
      {"frames_lost", s.lost},
      {"frames_skipped", s.skipped},
      {"table_detections", s.table_found},
      {"ball_detections", s.ball_found},
      {"tracked_frames", s.tracked},
      {"nis_mean", num(s.nis_mean)},
      {"nis_count", s.nis_count},
      {"table_pose", "per-frame PnP (the pose filter's kinematics are the simulated wrist's, not the footage's table)"},
      {"wrist",
       {{"simulated", true},
        {"ramps", s.ramps},
        {"commands", s.wrist_commands},
        {"limit_violations", s.limit_violations},
        {"max_commanded_angle_deg", s.max_commanded_angle_deg},
        {"max_commanded_rate_deg_s", s.max_commanded_rate_deg_s}}},
      {"limits_respected", s.limit_violations == 0},
      // Scored against the simulated table's truth in a simulated run; footage has none.
      {"observer_rmse_mm", nullptr},
      {"measurement_rmse_mm", nullptr},
      {"settling_time_s", nullptr},
      {"overshoot_pct", nullptr},
      {"push_recovery_s", nullptr},
      {"truth", "not scored (the frame source has no truth)"},
      {"stopped_early", s.stopped_early},
      {"wall_time_s", s.wall_s},
  };
  if (s.live) j["live"] = runtime::toJson(*s.live);
  if (!s.faults.empty()) j["faults"] = runtime::toJson(s.faults);
  return j;
}

void printTableBallFootageSummary(std::FILE* out, const TableBallFootageSummary& s, const TableBallConfig& cfg) {
  const auto n = [](std::uint64_t v) { return static_cast<unsigned long long>(v); };
  std::fprintf(out, "table_ball on footage (%s): stamps %.3f to %.3f s, %llu frames (%llu lost, %llu skipped)%s\n",
               s.source.c_str(), s.t_first, s.t_last, n(s.frames), n(s.lost), n(s.skipped),
               s.stopped_early ? ", stopped early" : "");
  std::fprintf(out, "  observer: table found in %llu frames, ball in %llu (%llu by edge tracking); table pose: "
                    "each frame's PnP\n",
               n(s.table_found), n(s.ball_found), n(s.tracked));
  if (s.nis_count > 0)
    std::fprintf(out, "  filter: mean NIS %.2f over %llu updates after the %.1f s warm-up (2 expected; the noise is "
                      "tuned for the filtered table pose)\n",
                 s.nis_mean, n(s.nis_count), cfg.warmup);
  else
    std::fprintf(out, "  filter: NIS not measured (no ball update after the %.1f s warm-up)\n", cfg.warmup);
  std::fprintf(out, "  wrist (simulated; its tilt is the observer's prior): %llu ramps, %llu commands, %llu limit "
                    "violations; max %.2f deg, %.1f deg/s (limits %.1f deg, %.1f deg/s)\n",
               n(s.ramps), n(s.wrist_commands), n(s.limit_violations), s.max_commanded_angle_deg,
               s.max_commanded_rate_deg_s, core::rad2deg(cfg.wrist.max_angle), core::rad2deg(cfg.wrist.max_rate));
  std::fprintf(out, "  observer error, settling, overshoot, push recovery: not scored: no truth (the footage does not "
                    "move with the simulated wrist)\n");
  if (s.live) {
    std::fprintf(out, "  %s\n", runtime::summaryLine(*s.live).c_str());
    std::fprintf(out, "  %s\n", runtime::processingLine(*s.live).c_str());
  }
  if (!s.faults.empty()) std::fprintf(out, "  %s\n", runtime::summaryLine(s.faults).c_str());
}

}  // namespace viewline::scenarios
