#include "viewline/scenarios/ball_catching/loop.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <mutex>
#include <string>
#include <thread>

#include "viewline/core/error.h"
#include "viewline/core/frames.h"
#include "viewline/core/random.h"
#include "viewline/estimation/consistency.h"
#include "viewline/io/log.h"
#include "viewline/runtime/delay_line.h"
#include "viewline/runtime/stale_frames.h"
#include "viewline/scenarios/ball_catching/detection.h"
#include "viewline/scenarios/ball_catching/planner_input.h"
#include "viewline/scenarios/ball_catching/recording.h"
#include "viewline/scenarios/ball_catching/robot_guard.h"
#include "viewline/scenarios/ball_catching/world.h"
#include "viewline/tracking/tracker.h"
#include "viewline/vision/ball_detector.h"

namespace viewline::scenarios {

namespace {

using Vector6 = Eigen::Matrix<double, 6, 1>;

// The tracker's verdict on one submitted image, as a gate decision (tracking::TrackGate's terms).
tracking::GateDecision decisionOf(const tracking::MeasurementOutcome& o, bool restarted) {
  if (o.fate != tracking::Fate::Fused) return tracking::GateDecision::Reject;
  if (restarted) return tracking::GateDecision::Restart;
  return o.seed ? tracking::GateDecision::Start : tracking::GateDecision::Accept;
}

// Everything one throw owns, and what happens at its two kinds of event: the control tick and
// a frame becoming ready.
class ThrowLoop {
public:
  ThrowLoop(const BallCatchingConfig& cfg, const sim::DragFlight& flight, ThrowFrames& source,
            std::vector<core::Camera> est_cams, robots::SimulatedCartesianRobot& robot, ThrowResult& res,
            const CatchHooks* hooks, runtime::TelemetrySink* tel, std::uint64_t seed, runtime::FaultPlan& faults)
      : cfg_(cfg), flight_(flight), source_(source), frames_(faults.wrap(source)), faults_(faults),
        guard_(robot, faults), est_cams_(std::move(est_cams)), robot_(robot),
        planner_(cfg.plannerConfig(), robot), tracker_(est_cams_, cfg.trackerConfig()), res_(res), hooks_(hooks), tel_(tel),
        noise_rng_(core::makeRng(core::deriveSeed(seed, 0xD37))),  // pixel_noise_px only
        planner_input_(cfg, est_cams_) {
    planner_.reset(0.0, cfg.robot.home);
    guard_.reset(robot.read(0.0));
    for (const auto& c : est_cams_) detectors_.emplace_back(cfg.detector, c);
  }

  // Control period: the estimates that have arrived reach the planner, then one set point.
  void tick(double t) {
    to_planner_.receive(t, [&](double t_avail, const estimation::StateEstimate& est) {
      const planning::PlannerUpdate u = planner_.update(t_avail, est);
      if (u.crossing && t_avail <= res_.t_cross - cfg_.prediction_lead_s) lead_prediction_ = u.crossing->p;
      if (tel_ && u.crossing) {
        Eigen::VectorXd x(4);
        x << u.crossing->t, u.crossing->p;
        Eigen::MatrixXd P = Eigen::MatrixXd::Zero(4, 4);
        P(0, 0) = u.crossing->var_t;
        P.bottomRightCorner<3, 3>() = u.crossing->cov_p;
        tel_->estimate({"crossing", t_avail, x, P});
      }
    });
    const robots::CartesianState sp = planner_.setpoint(t);
    guard_.send(sp);  // holds or halts when the robot fails (robot_guard.h)
    if (tel_) {
      Eigen::VectorXd u(6);
      u << sp.p, sp.v;
      tel_->command({"setpoint", t, u});
    }
  }

  // A frame is ready: grab, detect, track; the estimate leaves for the planner. Returns false
  // when the live view asks to stop.
  bool capture() {
    const std::optional<runtime::Frame> frame = frames_.grab();
    if (!frame) return true;  // dropped
    ++res_.frames;
    if (faults_.missesDeadline(*frame)) {  // stale: the planner has moved on (faults.h)
      faults_.note("frames_late_dropped");
      return true;
    }
    if (stale_.repeats(*frame)) {  // a frozen camera's old image with a new stamp (stale_frames.h)
      faults_.note("frames_frozen_dropped");
      return true;
    }
    const std::size_t ci = frame->camera;
    const CatchFrameTruth* truth = source_.lastTruth();
    if (truth && truth->in_front && truth->in_image && res_.t_first_visible < 0.0)
      res_.t_first_visible = frame->capture_time;
    if (tel_ && truth) tel_->estimate({"truth", frame->capture_time, flight_.state(frame->capture_time).p, {}});
    const std::optional<Eigen::Vector2d> det_px = measure(*frame);
    if (!hooks_ || !hooks_->on_frame) return true;
    CatchFrame f;
    f.throw_index = res_.index;
    f.camera = ci;
    f.camera_model = &est_cams_[ci];
    f.t = frame->capture_time;
    f.image = &frame->image;
    f.detection = det_px;
    f.crossing = planner_.target();
    f.hole = robot_.read(frame->capture_time).p;
    if (tracker_.initialised()) f.estimate = tracker_.state().x().head<3>();
    return hooks_->on_frame(f);
  }

  const planning::CatchPlanner& planner() const { return planner_; }
  const std::optional<Eigen::Vector3d>& leadPrediction() const { return lead_prediction_; }

private:
  // Detection (searching around the tracker's predicted pixel) and the tracker update. Returns
  // the pixel given to the tracker.
  std::optional<Eigen::Vector2d> measure(const runtime::Frame& frame) {
    const std::size_t ci = frame.camera;
    std::optional<Eigen::Vector2d> predicted;
    if (tracker_.initialised()) {
      const double tp = std::max(frame.stamp, tracker_.state().t());
      if (auto uv = est_cams_[ci].project(tracker_.predictAt(tp).x().head<3>())) predicted = *uv;
    }
    const auto det = detectCatchBall(cfg_, faults_, detectors_[ci], frame, frame.capture_time, predicted);
    if (!det) return std::nullopt;
    ++res_.detections;
    if (res_.t_first_detection < 0.0) res_.t_first_detection = frame.capture_time;
    const double sigma_det = det->sigma_detector_px, sigma = det->sigma_px;
    Eigen::Vector2d px = det->pixel;
    // The detector's own error as the tracker sees it: against the estimator camera's image of the
    // true ball at the stamp (calibration, registration, blur and stamp errors included).
    if (cfg_.object == "ball" && frame.stamp >= flight_.startTime() && frame.stamp <= flight_.endTime())
      if (const auto uv_true = est_cams_[ci].project(flight_.state(frame.stamp).p)) {
        res_.detection_sq_error_px2 += (px - *uv_true).squaredNorm();
        res_.told_variance_px2 += 2.0 * sigma_det * sigma_det;
        ++res_.detection_errors;
      }
    if (cfg_.pixel_noise_px > 0.0)
      px += cfg_.pixel_noise_px * Eigen::Vector2d(core::gaussian(noise_rng_), core::gaussian(noise_rng_));
    const tracking::ImageMeasurement m{next_id_++, ci, frame.stamp, px, sigma};
    if (tel_) tel_->measurement({"camera" + std::to_string(ci), m.t, m.id, m.uv, Eigen::Vector2d::Constant(sigma)});
    const int restarts_before = tracker_.trackState().restarts;
    if (const tracking::Refusal r = tracker_.submit(m); r != tracking::Refusal::None) {
      faults_.note(std::string("tracker_refused_") + tracking::toString(r));
      return px;
    }
    const auto o = tracker_.outcome(m.id);
    const bool fused = o && o->fate == tracking::Fate::Fused;
    if (fused) ++res_.fused;
    else ++res_.gated;
    consistency(m, o, tracker_.trackState().restarts > restarts_before);
    if (fused && tracker_.initialised())
      to_planner_.send(frame.stamp + cfg_.processing_latency, planner_input_.after(m, tracker_));
    if (tel_ && o) report(m, *o, tracker_.trackState().restarts > restarts_before);
    return px;
  }

  // The tracker's NIS and NEES samples (ThrowResult::nis, ::nees; counted as the tuning adapter does).
  void consistency(const tracking::ImageMeasurement&, const std::optional<tracking::MeasurementOutcome>& o,
                   bool restarted) {
    if (!o) return;
    const bool fused = o->fate == tracking::Fate::Fused;
    const bool starts = fused && (o->seed || restarted);
    if (fused && !starts && in_track_ >= kConsistencyBurnIn && std::isfinite(o->gate.mahalanobis))
      res_.nis.push_back(o->gate.mahalanobis);
    if (starts) in_track_ = 0;
    in_track_ += fused;
    if (fused && res_.fused == kNeesFusedImage && cfg_.object == "ball" && tracker_.initialised()) {
      const estimation::StateEstimate& s = tracker_.state();
      if (s.t() >= flight_.startTime() && s.t() <= flight_.endTime()) {
        const sim::FlightState f = flight_.state(s.t());
        Eigen::VectorXd x(6);
        x << f.p, f.v;
        res_.nees = estimation::nees(s, x);
      }
    }
  }

  void report(const tracking::ImageMeasurement& m, const tracking::MeasurementOutcome& o, bool restarted) {
    runtime::InnovationRecord r;
    r.channel = "ball";
    r.t = m.t;
    r.id = m.id;
    r.source = m.camera;
    r.rows = 2;  // one image: its two viewline rows
    r.decision = decisionOf(o, restarted);
    // The tracker's own gate statistic (dᵀ S⁻¹ d); it does not expose d and S themselves.
    if (r.decision != tracking::GateDecision::Start) r.nis = o.gate.mahalanobis;
    tel_->innovation(r);
    if (o.fate == tracking::Fate::Fused)
      tel_->estimate({"ball", tracker_.state().t(), tracker_.state().x(), tracker_.state().P()});
  }

  const BallCatchingConfig& cfg_;
  const sim::DragFlight& flight_;
  ThrowFrames& source_;            // the truth of the last frame
  runtime::FrameSource& frames_;  // the frames, through the injected faults
  runtime::FaultPlan& faults_;
  RobotGuard guard_;
  runtime::StaleFrameFilter stale_;
  std::vector<core::Camera> est_cams_;
  robots::SimulatedCartesianRobot& robot_;
  planning::CatchPlanner planner_;
  tracking::ViewlineTracker tracker_;
  std::vector<vision::BallDetector> detectors_;
  ThrowResult& res_;
  const CatchHooks* hooks_;
  runtime::TelemetrySink* tel_;
  core::Rng noise_rng_;
  runtime::DelayLine<estimation::StateEstimate> to_planner_;  // processing latency
  std::optional<Eigen::Vector3d> lead_prediction_;
  std::uint64_t next_id_ = 1;
  PlannerInput planner_input_;  // the fit of the track's images (planner_input.h)
  int in_track_ = 0;  ///< fused images of the current track (consistency burn-in)
};

}  // namespace

ThrowResult runThrow(const BallCatchingConfig& cfg, const sim::Scene& room, int index, std::uint64_t seed,
                     const CatchHooks* hooks, bool* interrupted) {
  const auto wall0 = std::chrono::steady_clock::now();
  ThrowResult res;
  res.index = index;
  res.seed = seed;
  core::Rng rng = core::makeRng(seed);
  std::shared_ptr<runtime::TelemetrySink> telemetry = hooks && hooks->telemetry ? hooks->telemetry(index) : nullptr;
  runtime::TelemetrySink* tel = telemetry.get();

  // 1. The throw and its true crossing of the plane through home (the planner moves the hole in
  // that plane; scoreThrow checks it against the robot's actual position).
  // A replay takes the throw recorded beside its frames (recording.h).
  const std::string replay_root = catchReplayRoot(cfg, hooks);
  const ThrowDraw d = replay_root.empty() ? drawThrow(cfg, rng) : readRecordedThrow(catchThrowDir(replay_root, index));
  res.release = d.release;
  res.launch_velocity = d.launch_velocity;
  res.launch_speed = d.launch_velocity.norm();
  res.launch_elevation_deg = core::rad2deg(std::atan2(d.launch_velocity.z(), d.launch_velocity.head<2>().norm()));
  res.distance = d.distance;
  const sim::DragFlight flight({d.release, d.launch_velocity}, 0.0, d.flight_time + cfg.post_crossing_s + 0.3,
                               cfg.throws.body);
  res.t_cross = crossingTime(flight, cfg.robot.home, cfg.box_normal);
  res.cross_true = flight.state(res.t_cross).p;
  const double t_end = res.t_cross + cfg.post_crossing_s;

  // 2. Robot, cameras (random phase per throw), and the loop's estimators.
  robots::SimulatedCartesianRobot robot(cfg.robot);
  robot.reset(0.0);
  const CatchWorld world(room, flight, cfg, robot);
  std::vector<core::Camera> est_cams;  // calibrated (rig:) or the render camera (inline cameras)
  for (std::size_t i = 0; i < cfg.activeCameras(); ++i) est_cams.push_back(cfg.cameras[i].estimatorCamera());
  std::unique_ptr<ThrowFrames> frames =
      replay_root.empty()
          ? std::make_unique<ThrowFrames>(throwCameras(cfg, rng), rng, cfg.render, world, t_end, cfg.object)
          : std::make_unique<ThrowFrames>(catchThrowDir(replay_root, index), est_cams.size());
  if (hooks && !hooks->record_dir.empty()) frames->record(catchThrowDir(hooks->record_dir, index), est_cams, d);
  ThrowFrames& source = *frames;
  runtime::FaultPlan faults(cfg.faults, core::deriveSeed(seed, 0xFA));
  ThrowLoop loop(cfg, flight, source, std::move(est_cams), robot, res, hooks, tel, seed, faults);

  // 3. One clock: the control tick every period, the next frame when it is ready.
  runtime::Scheduler sched;
  if (hooks) sched.setPacing(hooks->pacing);
  sched.every(0.0, cfg.control_period, runtime::priority::Control, [&](double t) { loop.tick(t); });
  bool source_done = false;
  std::function<void()> next_capture = [&] {
    const std::optional<double> t_ready = source.nextReadyTime();
    if (!t_ready) {
      source_done = true;
      return;
    }
    // A frame ready before now (an earlier end of exposure on another camera) is taken at once.
    sched.at(std::max(*t_ready, sched.now()), runtime::priority::Capture, [&](double) {
      if (!loop.capture()) sched.requestStop();
      next_capture();
    });
  };
  next_capture();
  while (!source_done && sched.step()) {
  }
  // The set points in flight reach the box after the last frame.
  if (!sched.stopRequested()) sched.runUntil(t_end + robot.commandLatency() + cfg.control_period);
  if (interrupted) *interrupted = sched.stopRequested();
  if (!sched.stopRequested()) frames->finishRecording();

  // 4. Outcome.
  scoreThrow(res, cfg, robot, loop.planner(), loop.leadPrediction());
  if (!faults.empty()) res.faults = faults.report();
  res.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  if (tel) tel->flush();
  return res;
}

std::function<std::shared_ptr<runtime::TelemetrySink>(int)> csvTelemetry(const std::string& dir) {
  return [dir](int i) -> std::shared_ptr<runtime::TelemetrySink> {
    char name[32];
    std::snprintf(name, sizeof name, "/throw_%03d", i);
    auto log = std::make_shared<io::LogDirectory>(dir + name);
    // The sink keeps its folder alive; both go (files closed) when the throw drops the sink.
    return std::shared_ptr<runtime::CsvSink>(new runtime::CsvSink(*log), [log](runtime::CsvSink* s) { delete s; });
  };
}

CatchSummary runBallCatching(const BallCatchingConfig& cfg, int throws, std::uint64_t seed, const CatchHooks& hooks) {
  if (throws < 1) throw core::InvalidInput("throws: expected >= 1");
  cfg.validate();
  if (cfg.onFootage())
    throw core::InvalidInput("cameras[].source: footage runs as one session (runCatchFootage, footage.h), not throw by throw");
  const auto wall0 = std::chrono::steady_clock::now();
  if (!hooks.record_dir.empty()) beginCatchRecording(hooks.record_dir, seed, throws, hooks.config_text);
  if (const std::string replay = catchReplayRoot(cfg, &hooks); !replay.empty()) checkCatchReplay(replay, seed, throws);
  core::Rng room_rng = core::makeRng(core::deriveSeed(seed, 0xB0B));
  const sim::Scene room = sim::makeRoom(cfg.room, room_rng);
  std::optional<RegistrationResult> registration;
  BallCatchingConfig registered = cfg;  // estimator cameras in the robot's world
  if (cfg.registration.enabled) registration = registerCamerasToRobot(registered, room, core::deriveSeed(seed, 0x4E6));
  std::vector<ThrowResult> results(static_cast<std::size_t>(throws));
  std::vector<char> completed(static_cast<std::size_t>(throws), 0);
  const bool serial = static_cast<bool>(hooks.on_frame) || cfg.threads <= 1;
  std::atomic<int> next{0}, done{0};
  std::mutex mu;
  std::exception_ptr error;
  auto worker = [&]() {
    while (true) {
      const int i = next++;
      if (i >= throws) return;
      bool interrupted = false;
      try {
        const auto k = static_cast<std::size_t>(i);
        results[k] = runThrow(registered, room, i, core::deriveSeed(seed, static_cast<std::uint64_t>(i)), &hooks,
                              &interrupted);
        completed[k] = !interrupted;
      } catch (...) {
        std::lock_guard<std::mutex> lock(mu);
        if (!error) error = std::current_exception();
        next = throws;
        return;
      }
      if (interrupted) {
        next = throws;  // the live view was closed: no more throws
        return;
      }
      const int dn = ++done;
      if (hooks.progress) {
        std::lock_guard<std::mutex> lock(mu);
        hooks.progress(dn, throws);
      }
    }
  };
  if (serial) {
    worker();
  } else {
    std::vector<std::thread> pool;
    for (int t = 0; t < cfg.threads; ++t) pool.emplace_back(worker);
    for (auto& t : pool) t.join();
  }
  if (error) std::rethrow_exception(error);
  std::vector<ThrowResult> kept;
  for (std::size_t k = 0; k < results.size(); ++k)
    if (completed[k]) kept.push_back(std::move(results[k]));
  CatchSummary s = summarise(std::move(kept), seed, std::move(registration));
  s.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  return s;
}

}  // namespace viewline::scenarios
