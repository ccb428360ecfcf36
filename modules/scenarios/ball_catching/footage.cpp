#include "viewline/scenarios/ball_catching/footage.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <string>

#include "viewline/core/error.h"
#include "viewline/core/random.h"
#include "viewline/robots/cartesian_robot.h"
#include "viewline/runtime/delay_line.h"
#include "viewline/runtime/recording.h"
#include "viewline/runtime/scheduler.h"
#include "viewline/runtime/stale_frames.h"
#include "viewline/scenarios/ball_catching/detection.h"
#include "viewline/scenarios/ball_catching/planner_input.h"
#include "viewline/scenarios/ball_catching/robot_guard.h"
#include "viewline/tracking/tracker.h"
#include "viewline/vision/ball_detector.h"

namespace viewline::scenarios {

std::string describeSource(const runtime::SourceConfig& s) { return runtime::describeSource(s); }

namespace {

// The rig's active cameras with their footage and calibrated image size.
std::vector<runtime::MergedCamera> footageCameras(const BallCatchingConfig& cfg) {
  std::vector<runtime::MergedCamera> cams;
  for (std::size_t i = 0; i < cfg.activeCameras(); ++i) {
    const CatchCameraConfig& c = cfg.cameras[i];
    const core::Camera est = c.estimatorCamera();
    cams.push_back({c.name, c.source, est.width, est.height});
  }
  return cams;
}

}  // namespace

CatchFootageFrames::CatchFootageFrames(const BallCatchingConfig& cfg, runtime::WallClock* clock)
    : runtime::MergedFrameSource(footageCameras(cfg), clock) {}

namespace {

// A fused state on its way to the planner: which track it belongs to and which frame it came from.
struct ToPlanner {
  int track = 0;
  std::uint64_t frame = 0;  // processing-timer key
  core::Timestamp stamp = 0.0;
  estimation::StateEstimate est;
};

// The session: what it owns and its two kinds of event (the control tick, a frame ready), as
// loop.cpp's ThrowLoop without the throw's truth.
class FootageSession {
public:
  FootageSession(const BallCatchingConfig& cfg, runtime::FrameSource& source, std::vector<core::Camera> est_cams,
                 robots::SimulatedCartesianRobot& robot, CatchFootageSummary& sum, const CatchHooks& hooks,
                 runtime::TelemetrySink* tel, std::uint64_t seed, runtime::FaultPlan& faults,
                 runtime::ProcessingTimer* timer, double t0)
      : cfg_(cfg), frames_(faults.wrap(source)), faults_(faults), guard_(robot, faults),
        est_cams_(std::move(est_cams)), robot_(robot), planner_(cfg.plannerConfig(), robot),
        tracker_(est_cams_, cfg.trackerConfig()), sum_(sum), hooks_(hooks), tel_(tel),
        noise_rng_(core::makeRng(core::deriveSeed(seed, 0xD37))), planner_input_(cfg, est_cams_), timer_(timer) {
    planner_.reset(t0, cfg.robot.home);
    guard_.reset(robot.read(t0));
    for (const auto& c : est_cams_) detectors_.emplace_back(cfg.detector, c);
  }

  // Control period: the fused states that have arrived reach the planner, then one set point.
  void tick(double t) {
    std::vector<std::uint64_t> timed;
    to_planner_.receive(t, [&](double t_avail, const ToPlanner& m) {
      if (timer_) timer_->resume(m.frame);
      if (sum_.tracks.empty() || m.track != sum_.tracks.back().track) startAttempt(t_avail, m);
      CatchFootageTrack& tr = sum_.tracks.back();
      tr.t_last = m.stamp;
      ++tr.planner_updates;
      const planning::PlannerUpdate u = planner_.update(t_avail, m.est);
      if (u.crossing) tr.last_prediction = u.crossing;
      if (tel_ && u.crossing) {
        Eigen::VectorXd x(4);
        x << u.crossing->t, u.crossing->p;
        Eigen::MatrixXd P = Eigen::MatrixXd::Zero(4, 4);
        P(0, 0) = u.crossing->var_t;
        P.bottomRightCorner<3, 3>() = u.crossing->cov_p;
        tel_->estimate({"crossing", t_avail, x, P});
      }
      if (timer_) timed.push_back(m.frame);
    });
    const robots::CartesianState sp = planner_.setpoint(t);
    guard_.send(sp);
    ++sum_.commands;
    if (tel_) {
      Eigen::VectorXd u(6);
      u << sp.p, sp.v;
      tel_->command({"setpoint", t, u});
    }
    // Where the hole is when the ball should cross: the planner's target at its crossing time.
    if (!sum_.tracks.empty()) {
      CatchFootageTrack& tr = sum_.tracks.back();
      const auto& target = planner_.target();
      if (target && !tr.hole_at_crossing && t >= target->t) tr.hole_at_crossing = robot_.read(target->t).p;
    }
    for (const std::uint64_t id : timed) timer_->finish(id);  // grab to the set point it led to
  }

  // A frame is ready: grab, detect, track; a fused state leaves for the planner. Returns false
  // when the live view asks to stop.
  bool capture() {
    const std::optional<runtime::Frame> frame = frames_.grab();
    if (!frame) return true;  // lost (counted by the source)
    const std::uint64_t id = ++frame_count_;
    if (timer_) timer_->resume(id);
    bool sent = false;
    bool go_on = true;
    if (faults_.missesDeadline(*frame)) {
      faults_.note("frames_late_dropped");
    } else if (stale_.repeats(*frame)) {  // a frozen camera's old image with a new stamp
      faults_.note("frames_frozen_dropped");
    } else {
      const std::optional<Eigen::Vector2d> det_px = measure(*frame, id, sent);
      if (hooks_.on_frame) {
        CatchFrame f;
        f.throw_index = 0;
        f.camera = frame->camera;
        f.camera_model = &est_cams_[frame->camera];
        f.t = frame->stamp;
        f.image = &frame->image;
        f.detection = det_px;
        f.crossing = planner_.target();
        f.hole = robot_.read(frame->stamp).p;
        if (tracker_.initialised()) f.estimate = tracker_.state().x().head<3>();
        go_on = hooks_.on_frame(f);
      }
    }
    if (timer_) {
      if (sent) timer_->pause(id);  // goes on when its state reaches the planner (tick)
      else timer_->finish(id);
    }
    return go_on;
  }

  // The end of the footage: the last track's decision.
  void finish() {
    if (!sum_.tracks.empty()) closeAttempt();
    sum_.tracks_started = trackNumber();
  }

private:
  // The tracker's track: its seeds less its restarts (a restart re-seeds the same ball's track
  // after rejections in a row, tracker.h).
  int trackCount() const { return tracker_.trackState().tracks_started - tracker_.trackState().restarts; }
  // The session's number of the current track (the tracker's count goes back to 0 when it is reset).
  int trackNumber() const { return tracks_before_ + trackCount(); }

  // A new track reached the planner: the previous attempt is closed and the planner starts again
  // from the robot's current commanded state (no jump, no velocity step).
  void startAttempt(double t, const ToPlanner& m) {
    if (!sum_.tracks.empty()) closeAttempt();
    const planning::CartesianSample s = planner_.profile().at(t);
    planner_.reset(t, s.p, s.v);
    CatchFootageTrack& tr = sum_.tracks.emplace_back();  // built in place: nothing copied
    tr.track = m.track;
    tr.t_first = m.stamp;
    tr.start = s.p;
  }

  void closeAttempt() {
    CatchFootageTrack& tr = sum_.tracks.back();
    tr.target = planner_.target();
    if (planner_.firstMoveTime()) tr.t_first_move = *planner_.firstMoveTime();
    if (planner_.commitTime()) tr.t_commit = *planner_.commitTime();
    if (planner_.giveUpTime()) tr.t_give_up = *planner_.giveUpTime();
    tr.decision = planner_.giveUpTime() ? "gave_up"
                  : planner_.committed() ? "committed"
                  : planner_.firstMoveTime() ? "moved"
                                             : "no_target";
  }

  // Detection (around the tracker's predicted pixel) and the tracker update; a fused image's state
  // leaves for the planner (`sent`). Returns the pixel given to the tracker.
  std::optional<Eigen::Vector2d> measure(const runtime::Frame& frame, std::uint64_t id, bool& sent) {
    const std::size_t ci = frame.camera;
    std::optional<Eigen::Vector2d> predicted;
    // A track that has coasted longer than max_coast_s is over (the next image starts a new one):
    // on footage the next ball comes after a pause, and a window where the old one would be now
    // only biases the search.
    if (tracker_.initialised() && frame.stamp - tracker_.state().t() <= cfg_.tracker.max_coast) {
      const double tp = std::max(frame.stamp, tracker_.state().t());
      if (auto uv = est_cams_[ci].project(tracker_.predictAt(tp).x().head<3>())) predicted = *uv;
    }
    const auto det = detectCatchBall(cfg_, faults_, detectors_[ci], frame, frame.stamp, predicted);
    if (!det) return std::nullopt;
    ++sum_.detections;
    ++sum_.cameras[ci].detections;
    const double sigma = det->sigma_px;
    Eigen::Vector2d px = det->pixel;
    if (cfg_.pixel_noise_px > 0.0)
      px += cfg_.pixel_noise_px * Eigen::Vector2d(core::gaussian(noise_rng_), core::gaussian(noise_rng_));
    // A pause longer than a track can coast (or than the tracker accepts as a step forward) ends
    // the ball: the tracker starts afresh, as for a new throw (its buffer and counters too, which
    // would refuse a stamp that far ahead).
    if (submitted_ && frame.stamp - last_submit_ > std::min(cfg_.tracker.max_coast, cfg_.tracker.max_forward_gap)) {
      tracks_before_ += trackCount();
      tracker_.reset();
      planner_input_.reset();
    }
    submitted_ = true;
    last_submit_ = std::max(last_submit_, frame.stamp);
    const tracking::ImageMeasurement m{next_id_++, ci, frame.stamp, px, sigma};
    if (tel_) tel_->measurement({"camera" + std::to_string(ci), m.t, m.id, m.uv, Eigen::Vector2d::Constant(sigma)});
    if (const tracking::Refusal r = tracker_.submit(m); r != tracking::Refusal::None) {
      faults_.note(std::string("tracker_refused_") + tracking::toString(r));
      ++sum_.refused;
      return px;
    }
    const auto o = tracker_.outcome(m.id);
    const bool fused = o && o->fate == tracking::Fate::Fused;
    if (fused) ++sum_.fused;
    else ++sum_.gated;
    if (fused && tracker_.initialised()) {
      to_planner_.send(frame.stamp + cfg_.processing_latency, {trackNumber(), id, frame.stamp,
                                                                planner_input_.after(m, tracker_)});
      sent = true;
    }
    if (tel_ && fused) tel_->estimate({"ball", tracker_.state().t(), tracker_.state().x(), tracker_.state().P()});
    return px;
  }

  const BallCatchingConfig& cfg_;
  runtime::FrameSource& frames_;  // the footage, through the injected faults
  runtime::FaultPlan& faults_;
  RobotGuard guard_;
  runtime::StaleFrameFilter stale_;
  std::vector<core::Camera> est_cams_;
  robots::SimulatedCartesianRobot& robot_;
  planning::CatchPlanner planner_;
  tracking::ViewlineTracker tracker_;
  std::vector<vision::BallDetector> detectors_;
  CatchFootageSummary& sum_;
  const CatchHooks& hooks_;
  runtime::TelemetrySink* tel_;
  core::Rng noise_rng_;
  runtime::DelayLine<ToPlanner> to_planner_;  // processing latency
  PlannerInput planner_input_;
  runtime::ProcessingTimer* timer_;
  std::uint64_t next_id_ = 1, frame_count_ = 0;
  bool submitted_ = false;   // an image went to the tracker
  double last_submit_ = 0.0;  // s, the newest stamp submitted
  int tracks_before_ = 0;     // tracks of the tracker before its last reset
};

// The session's clock: the control ticks from t0, every frame at its ready time, then the states
// and set points still in flight. `on_frame` runs after each frame. Returns the last ready time.
double runSession(const BallCatchingConfig& cfg, runtime::FrameSource& source, FootageSession& session,
                  const robots::SimulatedCartesianRobot& robot, double t0, const std::function<void()>& on_frame) {
  runtime::Scheduler sched(t0);
  sched.every(t0, cfg.control_period, runtime::priority::Control, [&](double t) { session.tick(t); });
  bool source_done = false;
  double t_last = t0;
  std::function<void()> next_capture = [&] {
    const std::optional<double> t_ready = source.nextReadyTime();
    if (!t_ready) {
      source_done = true;
      return;
    }
    t_last = std::max(t_last, *t_ready);
    sched.at(std::max(*t_ready, sched.now()), runtime::priority::Capture, [&](double) {
      if (!session.capture()) sched.requestStop();
      on_frame();
      next_capture();
    });
  };
  next_capture();
  while (!source_done && sched.step()) {
  }
  // The states and set points in flight reach the planner and the box after the last frame.
  if (!sched.stopRequested())
    sched.runUntil(sched.now() + cfg.processing_latency + robot.commandLatency() + 2.0 * cfg.control_period);
  session.finish();
  return t_last;
}

}  // namespace

CatchFootageSummary runCatchFootage(const BallCatchingConfig& cfg, std::uint64_t seed, const CatchHooks& hooks,
                                    runtime::WallClock* clock) {
  cfg.validate();
  if (!cfg.onFootage()) throw core::InvalidInput("cameras[].source: no active camera has footage (sim: runBallCatching)");
  if (!hooks.record_dir.empty())
    throw core::InvalidInput("--record: footage is recorded already (a recording holds simulated throws)");
  if (!hooks.replay_dir.empty()) throw core::InvalidInput("--replay: the cameras' footage is the input (cameras[].source)");
  const auto wall0 = std::chrono::steady_clock::now();
  CatchFootageSummary sum;
  sum.seed = seed;
  CatchFootageFrames source(cfg, clock);
  for (std::size_t i = 0; i < source.cameraCount(); ++i)
    sum.cameras.push_back({cfg.cameras[i].name, source.sourceName(i), 0, 0, 0});
  const std::optional<double> first = source.nextReadyTime();
  if (!first) throw core::InvalidInput("cameras[].source: the footage holds no frame");
  const double t0 = *first;
  std::shared_ptr<runtime::TelemetrySink> telemetry = hooks.telemetry ? hooks.telemetry(0) : nullptr;

  // Live: each frame timed from its grab to the set point its state led to, against one frame
  // period of the fastest camera.
  std::optional<runtime::ProcessingTimer> timer;
  double rate = 0.0;
  for (std::size_t i = 0; i < cfg.activeCameras(); ++i) rate = std::max(rate, cfg.throwRate(i));
  char origin[96];
  std::snprintf(origin, sizeof origin, "one frame period at %.4g fps (the fastest camera's rate_hz)", rate);
  if (source.live()) timer.emplace(1.0 / rate, clock);

  robots::SimulatedCartesianRobot robot(cfg.robot);
  robot.reset(t0);
  std::vector<core::Camera> est_cams;  // the rig's calibration, taken as registered (no marker in footage)
  for (std::size_t i = 0; i < cfg.activeCameras(); ++i) est_cams.push_back(cfg.cameras[i].estimatorCamera());
  runtime::FaultPlan faults(cfg.faults, core::deriveSeed(seed, 0xFA));
  FootageSession session(cfg, source, std::move(est_cams), robot, sum, hooks, telemetry.get(), seed, faults,
                         timer ? &*timer : nullptr, t0);

  const double t_last = runSession(cfg, source, session, robot, t0, [&] {
    if (hooks.progress) hooks.progress(static_cast<int>(source.delivered()), 0);
  });

  for (std::size_t i = 0; i < source.cameraCount(); ++i) {
    sum.cameras[i].frames = source.frames(i);
    sum.cameras[i].lost = source.lost(i);
    sum.frames += source.frames(i);
  }
  sum.t_first = t0;
  sum.t_last = t_last;
  sum.limit_violations = robot.velocityViolations() + robot.accelerationViolations();
  sum.refused_setpoints = robot.refusedSetpoints();
  sum.max_speed = robot.maxSpeedSeen();
  sum.max_acceleration = robot.maxAccelerationSeen();
  if (timer) sum.live = runtime::liveReport(source, *timer, origin);
  if (!faults.empty()) sum.faults = faults.report();
  if (telemetry) telemetry->flush();
  sum.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  return sum;
}

CatchFootageSummary runCatchFootageOnRecording(const BallCatchingConfig& cfg, std::uint64_t seed,
                                               const std::string& dir, const CatchHooks& hooks) {
  cfg.validate();
  if (!hooks.record_dir.empty()) throw core::InvalidInput("--record: the frames are recorded already");
  if (!hooks.replay_dir.empty()) throw core::InvalidInput("--replay: the recording is the input");
  const auto wall0 = std::chrono::steady_clock::now();
  runtime::RecordingSource source(dir);
  if (source.cameraCount() > cfg.activeCameras())
    throw core::InvalidInput(dir + ": a recording of " + std::to_string(source.cameraCount()) + " cameras, the config has " +
                             std::to_string(cfg.activeCameras()) + " active");
  CatchFootageSummary sum;
  sum.seed = seed;
  for (std::size_t i = 0; i < cfg.activeCameras(); ++i)
    sum.cameras.push_back({cfg.cameras[i].name, "recording " + dir, 0, 0, 0});
  const std::optional<double> first = source.nextReadyTime();
  if (!first) throw core::InvalidInput(dir + ": the recording holds no frame");
  const double t0 = *first;
  std::shared_ptr<runtime::TelemetrySink> telemetry = hooks.telemetry ? hooks.telemetry(0) : nullptr;
  robots::SimulatedCartesianRobot robot(cfg.robot);
  robot.reset(t0);
  std::vector<core::Camera> est_cams;  // the rig's calibration, taken as registered (as on footage)
  for (std::size_t i = 0; i < cfg.activeCameras(); ++i) est_cams.push_back(cfg.cameras[i].estimatorCamera());
  runtime::FaultPlan faults(cfg.faults, core::deriveSeed(seed, 0xFA));
  FootageSession session(cfg, source, std::move(est_cams), robot, sum, hooks, telemetry.get(), seed, faults, nullptr, t0);
  int grabs = 0;
  sum.t_last = runSession(cfg, source, session, robot, t0, [&] {
    ++grabs;
    if (hooks.progress) hooks.progress(grabs, 0);
  });
  for (const runtime::RecordingEntry& e : source.entries()) {
    if (e.camera >= sum.cameras.size()) continue;
    CatchFootageCamera& c = sum.cameras[e.camera];
    if (e.file.empty()) ++c.lost;
    else ++c.frames;
  }
  for (const CatchFootageCamera& c : sum.cameras) sum.frames += c.frames;
  sum.t_first = t0;
  sum.limit_violations = robot.velocityViolations() + robot.accelerationViolations();
  sum.refused_setpoints = robot.refusedSetpoints();
  sum.max_speed = robot.maxSpeedSeen();
  sum.max_acceleration = robot.maxAccelerationSeen();
  if (!faults.empty()) sum.faults = faults.report();
  if (telemetry) telemetry->flush();
  sum.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  return sum;
}

namespace {

nlohmann::json vec3(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

nlohmann::json crossingJson(const std::optional<planning::Crossing>& c) {
  if (!c) return nullptr;
  return {{"t_s", c->t},
          {"point_m", vec3(c->p)},
          {"std_m", c->sigmaMax()},
          {"std_t_s", std::sqrt(std::max(0.0, c->var_t))}};
}

}  // namespace

std::string footageSessionText(const std::string& scenario, const FootageSessionCounts& n) {
  std::string out;
  char line[512];
  std::snprintf(line, sizeof line, "%s on footage: one session, stamps %.3f to %.3f s, %llu frames, %llu detections\n",
                scenario.c_str(), n.t_first, n.t_last, static_cast<unsigned long long>(n.frames),
                static_cast<unsigned long long>(n.detections));
  out += line;
  for (const auto& c : n.cameras) {
    std::snprintf(line, sizeof line, "  camera %-8s %s: %llu frames, %llu lost, %llu detections\n", c.name.c_str(),
                  c.source.c_str(), static_cast<unsigned long long>(c.frames), static_cast<unsigned long long>(c.lost),
                  static_cast<unsigned long long>(c.detections));
    out += line;
  }
  std::snprintf(line, sizeof line, "  tracker: %d tracks started, %llu images fused, %llu gated, %llu refused\n",
                n.tracks_started, static_cast<unsigned long long>(n.fused), static_cast<unsigned long long>(n.gated),
                static_cast<unsigned long long>(n.refused));
  out += line;
  return out;
}

nlohmann::json footageSessionJson(const std::string& scenario, const FootageSessionCounts& n) {
  nlohmann::json cams = nlohmann::json::array();
  for (const auto& c : n.cameras)
    cams.push_back({{"name", c.name}, {"source", c.source}, {"frames", c.frames}, {"lost", c.lost},
                    {"detections", c.detections}});
  return {{"scenario", scenario},
          {"mode", "footage"},
          {"seed", n.seed},
          {"cameras", cams},
          {"footage_s", {{"first_stamp", n.t_first}, {"last_stamp", n.t_last}}},
          {"frames", n.frames},
          {"detections", n.detections},
          {"fused", n.fused},
          {"gated", n.gated},
          {"refused", n.refused},
          {"tracks_started", n.tracks_started}};
}

std::string footageLiveText(const std::optional<runtime::LiveReport>& live) {
  if (!live) return {};
  return "  " + runtime::summaryLine(*live) + "\n  " + runtime::processingLine(*live) + "\n";
}

nlohmann::json footageSummaryJson(const CatchFootageSummary& s, const BallCatchingConfig& cfg) {
  nlohmann::json tracks = nlohmann::json::array();
  for (const auto& t : s.tracks) {
    nlohmann::json j = {{"track", t.track},
                        {"t_first_s", t.t_first},
                        {"t_last_s", t.t_last},
                        {"planner_updates", t.planner_updates},
                        {"start_m", vec3(t.start)},
                        {"decision", t.decision},
                        {"target", crossingJson(t.target)},
                        {"last_prediction", crossingJson(t.last_prediction)},
                        {"t_first_move_s", t.t_first_move < 0.0 ? nlohmann::json(nullptr) : nlohmann::json(t.t_first_move)},
                        {"t_commit_s", t.t_commit < 0.0 ? nlohmann::json(nullptr) : nlohmann::json(t.t_commit)},
                        {"t_give_up_s", t.t_give_up < 0.0 ? nlohmann::json(nullptr) : nlohmann::json(t.t_give_up)}};
    j["hole_at_crossing_m"] = t.hole_at_crossing ? vec3(*t.hole_at_crossing) : nlohmann::json(nullptr);
    j["hole_to_target_mm"] = t.hole_at_crossing && t.target
                                 ? nlohmann::json(1e3 * (*t.hole_at_crossing - t.target->p).norm())
                                 : nlohmann::json(nullptr);
    tracks.push_back(j);
  }
  nlohmann::json j = footageSessionJson(cfg.name, s);
  j["tracks"] = tracks;
  j["robot"] = {{"commands", s.commands},
                {"limit_violations", s.limit_violations},
                {"refused_setpoints", s.refused_setpoints},
                {"max_speed", s.max_speed},
                {"max_acceleration", s.max_acceleration},
                {"v_max", cfg.robot.limits.v_max.x()},
                {"a_max", cfg.robot.limits.a_max.x()}};
  j["catch_rate_all"] = nullptr;
  j["truth"] = "not scored (the frame source has no truth)";
  j["registration"] = "off on footage (the rig's calibration is used as registered)";
  j["wall_time_s"] = s.wall_s;
  if (s.live) j["live"] = runtime::toJson(*s.live);
  if (!s.faults.empty()) j["faults"] = runtime::toJson(s.faults);
  return j;
}

std::string footageSummaryText(const CatchFootageSummary& s, const BallCatchingConfig& cfg) {
  std::string out = footageSessionText(cfg.name, s);
  char line[512];
  for (const auto& t : s.tracks) {
    if (t.target) {
      std::snprintf(line, sizeof line,
                    "  track %d (%.3f-%.3f s, %d updates): %s; crossing (%.3f, %.3f, %.3f) m at %.3f s, std %.1f mm",
                    t.track, t.t_first, t.t_last, t.planner_updates, t.decision.c_str(), t.target->p.x(), t.target->p.y(),
                    t.target->p.z(), t.target->t, 1e3 * t.target->sigmaMax());
      out += line;
      if (t.hole_at_crossing) {
        std::snprintf(line, sizeof line, "; hole %.1f mm from it then\n", 1e3 * (*t.hole_at_crossing - t.target->p).norm());
        out += line;
      } else {
        out += "; footage ended before it\n";
      }
    } else {
      std::snprintf(line, sizeof line, "  track %d (%.3f-%.3f s, %d updates): %s\n", t.track, t.t_first, t.t_last,
                    t.planner_updates, t.decision.c_str());
      out += line;
    }
  }
  std::snprintf(line, sizeof line,
                "  robot: %zu set points, %zu limit violations, %zu refused; max speed %.3f m/s, max acceleration "
                "%.2f m/s²\n",
                s.commands, s.limit_violations, s.refused_setpoints, s.max_speed, s.max_acceleration);
  out += line;
  out += "  catch rate: not scored: no truth (footage has no flight to score the catch against)\n";
  out += "  registration: off on footage (the rig's calibration is used as registered)\n";
  out += footageLiveText(s.live);
  return out;
}

}  // namespace viewline::scenarios
