#include "viewline/scenarios/mobile_capture/footage.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <memory>

#include "viewline/control/mobile_capture_control.h"
#include "viewline/core/error.h"
#include "viewline/core/interrupt.h"
#include "viewline/core/random.h"
#include "viewline/runtime/merged_source.h"
#include "viewline/runtime/scheduler.h"
#include "viewline/runtime/source_config.h"
#include "viewline/scenarios/mobile_capture/chase.h"
#include "viewline/scenarios/mobile_capture/world.h"
#include "viewline/tracking/unicycle_tracker.h"
#include "viewline/vision/ball_detector.h"

namespace viewline::scenarios {

using Eigen::Vector2d;
using Eigen::Vector3d;
using namespace mobile_capture;

namespace {

// A command within a limit, with a relative tolerance for the clamps' own rounding.
bool within(double value, double limit) { return std::abs(value) <= limit * (1.0 + 1e-9); }

}  // namespace

bool mobileCaptureOnFootage(const MobileCaptureConfig& cfg) {
  return !cfg.source.simulated() && cfg.source.kind != runtime::SourceKind::Recording;
}

MobileFootageSummary runMobileCaptureFootage(const MobileCaptureConfig& cfg, std::uint64_t seed,
                                             runtime::WallClock* clock, const MobileCaptureHooks* hooks) {
  cfg.validate();
  if (!mobileCaptureOnFootage(cfg))
    throw core::InvalidInput(std::string("source.kind: expected footage (images, video or v4l2), got ") +
                             runtime::toString(cfg.source.kind));
  if (hooks && !hooks->record_dir.empty()) throw core::InvalidInput("--record: footage is recorded already");
  if (hooks && !hooks->replay_dir.empty()) throw core::InvalidInput("--replay: the footage is the input (source:)");
  if (hooks && hooks->pacing.paced())
    throw core::InvalidInput("--realtime: footage is paced by its source (source.pace: true)");
  if (hooks && hooks->telemetry)
    throw core::InvalidInput("telemetry: the footage session logs footage.csv (logFootage), not the loop's channels");
  const auto wall0 = std::chrono::steady_clock::now();
  MobileFootageSummary sum;
  sum.seed = seed;
  sum.source = runtime::describeSource(cfg.source);
  runtime::SingleCameraFootage opened = runtime::openSingleCameraFootage(cfg.source, clock, "the head camera");
  const std::unique_ptr<runtime::FrameSource>& source = opened.source;
  const double t0 = opened.t0;
  runtime::LiveFrameSource* const live = opened.live;

  // The fixed camera: the robot and its head held at their start pose (header comment).
  RobotSim robot(cfg);
  const robots::BasePose pose = robot.base.pose();
  sum.robot = pose;
  sum.head = robot.q;
  core::Camera camera = estimatorCamera(cfg);
  camera.c_M_w = estimatorCamera_c_M_w(cfg, robot.head, robot.reading());

  runtime::FaultPlan faults(cfg.faults, core::deriveSeed(seed, 0xFA));
  runtime::FrameSource& frames = faults.wrap(*source);
  // The simulated loop's perception and commands (chase.h), on the held robot.
  ChaseController chase(cfg);
  const tracking::UnicycleTracker& track = chase.track();
  // Live: each frame timed from its grab to its capture plan, against one vision period.
  std::optional<runtime::ProcessingTimer> timer;
  if (live) timer.emplace(cfg.vision_period, clock);

  FrameScreen screen;  // late, frozen and stale-stamp frames dropped (chase.h)
  const unsigned width = camera.width, height = camera.height;

  auto process = [&](const runtime::Frame& frame) {
    const double t = frame.stamp;
    MobileFootageSample row;
    row.t = t;
    row.sequence = frame.sequence;
    const ChaseObservation o = chase.frame(faults, frame, camera, pose);
    if (o.floor) {
      row.detected = true;
      row.measured = o.floor->z;
      ++sum.detections;
      row.fused = o.update->fused;
    }
    if (track.valid()) {
      const Eigen::VectorXd& x = track.state().x();
      const planning::CapturePlan& plan = chase.plan();
      row.track_valid = true;
      row.position = track.positionAt(t);
      row.heading = x[2];
      row.speed = x[3];
      row.turn_rate = x[4];
      row.reachable = plan.reachable;
      row.intercept = plan.point;
      row.intercept_time = t + plan.time;
    }
    sum.samples.push_back(row);
    if (hooks && hooks->on_frame) {
      MobileCaptureFrame f;
      f.t = t;
      f.image = &frame.image;
      f.detected = row.detected;
      if (o.pixel) f.pixel = *o.pixel;
      f.robot = pose;
      f.joints = robot.q;
      // No truth on footage: the view centres on (and marks) the tracked position instead.
      f.object_true = row.track_valid ? row.position : row.detected ? row.measured : Vector2d(pose.x, pose.y);
      f.fused = row.fused;
      f.estimate_valid = track.valid();
      if (track.valid()) f.estimate = track.state().x();
      f.prediction = chase.prediction();
      f.plan = chase.plan();
      f.mode = chase.mode();
      hooks->on_frame(f);
    }
  };

  // Control period: the laws' commands from the held pose, checked and counted, never executed.
  auto tick = [&](double t) {
    // The held robot does not turn: the search bearing stays where the last estimate put it.
    const ChaseCommand c = chase.command(t, pose, robot.head, robot.q, 0.0);
    const control::BaseCommand& cmd = c.base;
    const robots::PanTiltJoints& head_target = c.head;
    ++sum.base_commands;
    ++sum.head_commands;
    sum.max_speed = std::max(sum.max_speed, std::abs(cmd.v));
    sum.max_turn_rate = std::max(sum.max_turn_rate, std::abs(cmd.omega));
    const auto& h = cfg.head;
    const bool head_ok = head_target.tilt >= h.tilt_min - 1e-9 && head_target.tilt <= h.tilt_max + 1e-9 &&
                         head_target.pan >= h.pan_min - 1e-9 && head_target.pan <= h.pan_max + 1e-9;
    if (!within(cmd.v, cfg.base.max_speed) || !within(cmd.omega, cfg.base.max_turn_rate) || !head_ok)
      ++sum.limit_violations;
  };

  runtime::Scheduler sched(t0);
  sched.every(t0, cfg.controlPeriod(), runtime::priority::Control, tick);
  bool source_done = false;
  double t_last = t0;
  std::uint64_t frame_id = 0;
  std::function<void()> next_capture = [&] {
    const std::optional<double> t_ready = frames.nextReadyTime();
    if (!t_ready) {
      source_done = true;
      return;
    }
    sched.at(std::max(*t_ready, sched.now()), runtime::priority::Capture, [&](double) {
      std::optional<runtime::Frame> frame = frames.grab();
      if (!frame) {
        ++sum.lost;
      } else {
        if (frame->image.type() != CV_8UC3)
          throw core::InvalidInput("source: " + sum.source + ": frame " + std::to_string(frame->sequence) +
                                   " is not a colour (8-bit BGR) image: the detector segments red");
        if (static_cast<unsigned>(frame->image.cols) != width || static_cast<unsigned>(frame->image.rows) != height)
          throw core::InvalidInput("source: " + sum.source + ": frame " + std::to_string(frame->sequence) + " is " +
                                   std::to_string(frame->image.cols) + "x" + std::to_string(frame->image.rows) +
                                   " px, the head camera is " + std::to_string(width) + "x" + std::to_string(height) +
                                   " px");
        ++sum.frames;
        t_last = std::max(t_last, frame->stamp);
        const std::uint64_t id = ++frame_id;
        if (timer) timer->resume(id);
        if (screen.admit(faults, *frame)) process(*frame);
        if (timer) timer->finish(id);
      }
      if (hooks && hooks->quit_requested && hooks->quit_requested()) sched.requestStop();
      next_capture();
    });
  };
  next_capture();
  while (!source_done && sched.step()) {
  }
  sum.interrupted = sched.stopRequested();

  sum.t_first = t0;
  sum.t_last = t_last;
  sum.gate = track.gate().counts();
  if (timer && live) sum.live = runtime::liveReport(*live, *timer, "one vision period (timing.vision_period)");
  if (!faults.empty()) sum.faults = faults.report();
  sum.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  return sum;
}

void logFootage(const MobileFootageSummary& s, io::LogDirectory& log) {
  if (!log.enabled()) return;
  auto& csv = log.stream("footage", {"t", "sequence", "detected", "fused", "measured_x", "measured_y", "track_valid",
                                     "x", "y", "theta", "v", "omega", "reachable", "intercept_x", "intercept_y",
                                     "intercept_t"},
                         17);
  for (const MobileFootageSample& r : s.samples)
    csv.row({r.t, static_cast<double>(r.sequence), r.detected ? 1.0 : 0.0, r.fused ? 1.0 : 0.0, r.measured.x(),
             r.measured.y(), r.track_valid ? 1.0 : 0.0, r.position.x(), r.position.y(), r.heading, r.speed, r.turn_rate,
             r.reachable ? 1.0 : 0.0, r.intercept.x(), r.intercept.y(), r.intercept_time});
  log.flush();
}

namespace {

nlohmann::json finiteOrNull(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }
nlohmann::json pointOrNull(const Vector2d& p) {
  return p.allFinite() ? nlohmann::json({p.x(), p.y()}) : nlohmann::json(nullptr);
}
// The last frame with a track, if any.
const MobileFootageSample* lastTracked(const MobileFootageSummary& s) {
  for (auto it = s.samples.rbegin(); it != s.samples.rend(); ++it)
    if (it->track_valid) return &*it;
  return nullptr;
}

}  // namespace

nlohmann::json footageSummaryJson(const MobileFootageSummary& s, const MobileCaptureConfig& cfg) {
  std::uint64_t tracked = 0, fused = 0;
  for (const auto& r : s.samples) tracked += r.track_valid, fused += r.fused;
  nlohmann::json object = nullptr;
  if (const MobileFootageSample* r = lastTracked(s))
    object = {{"t_s", r->t},
              {"position_m", pointOrNull(r->position)},
              {"speed_m_s", finiteOrNull(r->speed)},
              {"heading_rad", finiteOrNull(r->heading)},
              {"turn_rate_rad_s", finiteOrNull(r->turn_rate)},
              {"intercept",
               {{"reachable", r->reachable},
                {"point_m", pointOrNull(r->intercept)},
                {"t_s", finiteOrNull(r->intercept_time)}}}};
  nlohmann::json j = {
      {"mode", "footage"},
      {"seed", s.seed},
      {"source", s.source},
      {"footage_s", {{"first_stamp", s.t_first}, {"last_stamp", s.t_last}}},
      {"frames", s.frames},
      {"lost", s.lost},
      {"detections", s.detections},
      {"detection_rate", s.frames > 0 ? nlohmann::json(static_cast<double>(s.detections) / s.frames) : nlohmann::json(nullptr)},
      {"fused", fused},
      {"frames_tracked", tracked},
      {"gate", {{"starts", s.gate.starts}, {"accepted", s.gate.accepted}, {"rejected", s.gate.rejected},
                {"restarts", s.gate.restarts}}},
      {"object_last", object},
      {"robot",
       {{"model", "held at its start pose (fixed camera): commands computed, not executed"},
        {"pose", {s.robot.x, s.robot.y, s.robot.theta}},
        {"head_joints_rad", {s.head.tilt, s.head.pan}},
        {"base_commands", s.base_commands},
        {"head_commands", s.head_commands},
        {"limit_violations", s.limit_violations},
        {"max_speed_m_s", s.max_speed},
        {"max_turn_rate_rad_s", s.max_turn_rate},
        {"speed_limit_m_s", cfg.base.max_speed},
        {"turn_rate_limit_rad_s", cfg.base.max_turn_rate}}},
      {"capture_success_rate", nullptr},
      {"capture_time_s", nullptr},
      {"truth", "not scored (the frame source has no truth)"},
      {"rig", cfg.rig ? nlohmann::json(cfg.rig->folder) : nlohmann::json(nullptr)},
      {"wall_time_s", s.wall_s}};
  if (s.interrupted) j["interrupted"] = true;  // ended before the footage's end (a signal, or the view's quit)
  if (s.live) j["live"] = runtime::toJson(*s.live);
  if (!s.faults.empty()) j["faults"] = runtime::toJson(s.faults);
  return j;
}

std::string footageSummaryText(const MobileFootageSummary& s, const MobileCaptureConfig& cfg) {
  std::string out;
  char line[512];
  std::snprintf(line, sizeof line, "mobile_capture on footage (%s): one session%s, stamps %.3f to %.3f s\n",
                s.source.c_str(), s.interrupted ? " (interrupted)" : "", s.t_first, s.t_last);
  out += line;
  std::snprintf(line, sizeof line, "  %llu frames, %llu lost, %llu with a detection; track: %llu starts, %llu accepted, "
                "%llu rejected, %llu restarts\n",
                static_cast<unsigned long long>(s.frames), static_cast<unsigned long long>(s.lost),
                static_cast<unsigned long long>(s.detections), static_cast<unsigned long long>(s.gate.starts),
                static_cast<unsigned long long>(s.gate.accepted), static_cast<unsigned long long>(s.gate.rejected),
                static_cast<unsigned long long>(s.gate.restarts));
  out += line;
  if (const MobileFootageSample* r = lastTracked(s)) {
    std::snprintf(line, sizeof line,
                  "  object at %.3f s: (%.3f, %.3f) m, speed %.3f m/s; intercept (%.3f, %.3f) m at %.3f s (%s)\n", r->t,
                  r->position.x(), r->position.y(), r->speed, r->intercept.x(), r->intercept.y(), r->intercept_time,
                  r->reachable ? "reachable" : "not reachable in time");
    out += line;
  } else {
    out += "  object: never tracked\n";
  }
  std::snprintf(line, sizeof line,
                "  robot held at (%.3f, %.3f) m, heading %.1f deg (fixed camera): %llu base and %llu head commands "
                "computed, not executed; %llu outside the limits (max |v| %.3f of %.3f m/s, |omega| %.3f of %.3f rad/s)\n",
                s.robot.x, s.robot.y, s.robot.theta * 180.0 / M_PI, static_cast<unsigned long long>(s.base_commands),
                static_cast<unsigned long long>(s.head_commands), static_cast<unsigned long long>(s.limit_violations),
                s.max_speed, cfg.base.max_speed, s.max_turn_rate, cfg.base.max_turn_rate);
  out += line;
  out += "  capture time and rate: not scored: no truth (footage has no object path to grasp against)\n";
  if (s.live) {
    out += "  " + runtime::summaryLine(*s.live) + "\n";
    out += "  " + runtime::processingLine(*s.live) + "\n";
  }
  if (!s.faults.empty()) out += "  " + runtime::summaryLine(s.faults) + "\n";
  return out;
}

}  // namespace viewline::scenarios
