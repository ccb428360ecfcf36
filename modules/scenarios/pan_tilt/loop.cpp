#include "viewline/scenarios/pan_tilt/loop.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include "viewline/core/error.h"
#include "viewline/core/random.h"
#include "viewline/runtime/delay_line.h"
#include "viewline/runtime/live.h"
#include "viewline/runtime/recording.h"
#include "viewline/runtime/stale_frames.h"
#include "viewline/scenarios/pan_tilt/faults.h"
#include "viewline/scenarios/pan_tilt/world.h"

namespace viewline::scenarios {

using Eigen::Vector2d;
using Eigen::Vector3d;

std::string truthChannel(const std::string& controller) { return controller + "_truth"; }
std::string imageErrorChannel(const std::string& controller) { return controller + "_image_error_px"; }
const std::vector<std::string>& ptuTableColumns() {
  static const std::vector<std::string> c = {"joint_t", "pan", "tilt", "noise_x", "noise_y", "R_xx", "R_xy", "R_yy"};
  return c;
}

namespace {

/// A frame after detection, on its way to the controller.
struct Processed {
  std::size_t index = 0;
  runtime::Frame frame;
  pan_tilt::FrameTruth truth;
  control::TargetObservation obs;
  Vector2d meas_px = Vector2d::Constant(std::nan(""));
};

/// The commands the law still has to account for: those issued within the unit's latency plus
/// two periods (at least the last two). Not a delivery queue: the unit applies each command after
/// its latency itself; the law predicts the joints at the effect time from these.
class CommandsInFlight {
public:
  CommandsInFlight(double latency, double period) : keep_(latency + 2.0 * period) {}
  const std::vector<robots::IssuedCommand>& all() const { return recent_; }
  void issued(double t, const Vector2d& qdot) {
    recent_.push_back({t, qdot});
    while (recent_.size() > 2 && recent_.front().t < t - keep_) recent_.erase(recent_.begin());
  }

private:
  double keep_;
  std::vector<robots::IssuedCommand> recent_;
};

/// The gate's decision for ours' last observe(), from the controller's own report: a measurement
/// that (re)initialised a filter without a live track starts one; one that re-initialised it
/// after rejections in a row restarts it.
tracking::GateDecision decisionOf(const tracking::PlanarTargetFilter::Update& u, bool started) {
  if (started) return tracking::GateDecision::Start;
  if (!u.accepted) return tracking::GateDecision::Reject;
  return u.reinitialized ? tracking::GateDecision::Restart : tracking::GateDecision::Accept;
}

Eigen::VectorXd vec(const Vector2d& v) { return Eigen::VectorXd(v); }

/// The truth columns of a pan-tilt recording (FrameTruth: plane m, pixel px, image error px).
const std::vector<std::string> kTruthColumns = {"plane_x", "plane_y", "px_u", "px_v", "error_px"};

pan_tilt::FrameTruth truthFromValues(const std::vector<double>& v) {
  pan_tilt::FrameTruth t;
  t.plane = Vector2d(v[0], v[1]);
  t.px = Vector2d(v[2], v[3]);
  t.error_px = v[4];
  return t;
}

/// "30" or "29.97": a frame rate as a person writes it.
std::string fpsText(double fps) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", fps);
  return text;
}

pan_tilt::FrameTruth noTruth() {
  pan_tilt::FrameTruth t;
  t.plane = t.px = Vector2d::Constant(std::nan(""));
  t.error_px = std::nan("");
  return t;
}

}  // namespace

std::optional<ScreenMeasurement> measureOnScreen(const core::Camera& cam, const Vector2d& px,
                                                 const Eigen::Isometry3d& f_M_screen, const Vector2d& noise) {
  const Vector3d ray_f = cam.rayThroughPixel_w(px);
  const Vector3d c_f = cam.center_w();
  const Eigen::Isometry3d screen_M_f = f_M_screen.inverse();
  const Vector3d o_s = screen_M_f * c_f;
  const Vector3d d_s = screen_M_f.linear() * ray_f;
  if (!(d_s.z() > 1e-9)) return std::nullopt;
  const double lambda = -o_s.z() / d_s.z();
  const Vector3d hit = o_s + lambda * d_s;
  ScreenMeasurement m;
  m.plane = hit.head<2>() + noise;
  m.in_camera = cam.toCamera(f_M_screen * Vector3d(m.plane.x(), m.plane.y(), 0.0));
  return m;
}

PanTiltRunMetrics runPanTilt(const PanTiltScenarioConfig& cfg, std::uint64_t seed, PanTiltControllerKind kind,
                             const PanTiltRunIo& io) {
  cfg.validate();
  auto wall0 = std::chrono::steady_clock::now();
  // A FLIR PTU (or its emulator) replaces the simulated unit: the camera rides on it, the laws
  // drive it, and the run is paced to the wall clock, the unit's time.
  std::unique_ptr<robots::FlirPtu> hardware;
  if (cfg.hardware_unit) hardware = std::make_unique<robots::FlirPtu>(*cfg.hardware_unit);
  pan_tilt::World world(cfg, seed, hardware.get());
  robots::PanTiltUnit& unit = world.actuator();
  const robots::PanTiltLimits& limits = unit.limits();  // the unit owns its limits
  if (hardware) {  // the simulated unit's start: pointing at the path's start plus the offset
    hardware->moveTo(world.unit().params().q0.cwiseMax(limits.q_min).cwiseMin(limits.q_max), 0.5 * limits.qdot_max);
    hardware->await(10.0);
    wall0 = std::chrono::steady_clock::now();  // the time per frame is the loop's, as on the simulated unit
  }
  const double latency = unit.commandLatency();  // the unit owns its latency; the laws ask it
  const robots::PanTiltKinematics& kin_model = world.modelKinematics();
  core::Camera model_cam = panTiltModelCamera(cfg);  // pose set per frame
  vision::ScreenTargetDetector detector(cfg.detector);

  std::unique_ptr<control::PanTiltController> ctrl;
  control::PredictivePanTiltController* ours = nullptr;
  if (kind == PanTiltControllerKind::Predictive) {
    control::PredictiveConfig pc = cfg.control;
    pc.filter.particle_seed = core::deriveSeed(seed, 78);  // (waypoint_particles; the replay uses the same)
    auto p = std::make_unique<control::PredictivePanTiltController>(pc, limits, latency, world.f_M_screen(), kin_model);
    ours = p.get();
    ctrl = std::move(p);
  } else {
    ctrl = std::make_unique<control::BaselinePanTiltController>(cfg.control.servo, limits, latency, cfg.control.limits,
                                                                kin_model);
  }
  const std::string name = ctrl->name();
  pan_tilt::Scorer score(cfg, world.occlusionStart(), world.occlusionEnd(), world.sigma(), name);
  const double period = 1.0 / cfg.fps;
  const auto n_frames = static_cast<std::size_t>(std::floor(cfg.duration * cfg.fps));
  // The frame source: the renderer, or the config's source, or a recording of this controller's run.
  pan_tilt::RendererSource renderer(world, n_frames);
  std::unique_ptr<runtime::FrameSource> external;
  const runtime::RecordingSource* recorded = nullptr;
  if (!io.replay_dir.empty()) {
    auto r = std::make_unique<runtime::RecordingSource>(io.replay_dir + "/" + name);
    recorded = r.get();
    external = std::move(r);
  } else if (!cfg.source.simulated()) {
    external = runtime::makeFrameSource(cfg.source, io.clock);
    recorded = dynamic_cast<const runtime::RecordingSource*>(external.get());
  }
  // A live source runs at its own pace: what the loop misses of it is counted and timed (live.h).
  const runtime::LiveFrameSource* live = dynamic_cast<const runtime::LiveFrameSource*>(external.get());
  std::optional<runtime::ProcessingTimer> timer;
  if (live) timer.emplace(period, io.clock);
  const bool has_truth = !external || (recorded != nullptr && recorded->truthColumns() == kTruthColumns);
  runtime::FrameSource* grabber = external ? external.get() : &renderer;
  std::unique_ptr<runtime::RecordingWriter> writer;
  std::unique_ptr<runtime::RecordingFrameSource> recorder;
  if (!io.record_dir.empty()) {
    writer = std::make_unique<runtime::RecordingWriter>(io.record_dir + "/" + name);
    writer->setCamera(0, panTiltModelCamera(cfg));  // the calibration the controllers use
    if (!io.config_text.empty()) writer->setConfig(io.config_text);
    if (has_truth) writer->setTruthColumns(kTruthColumns);
    writer->setTable(kPtuTable, ptuTableColumns());  // a replay without the unit needs its readings
    recorder = std::make_unique<runtime::RecordingFrameSource>(*grabber, *writer);
    grabber = recorder.get();
  }
  runtime::FaultPlan faults(cfg.faults, core::deriveSeed(seed, 0xFA));
  runtime::FrameSource& source = faults.wrap(*grabber);
  runtime::StaleFrameFilter stale;
  CommandsInFlight recent(latency, period);
  runtime::DelayLine<Processed> to_controller;  // the processing delay
  runtime::TelemetrySink* tel = io.telemetry;
  if (io.frames != nullptr) io.frames->runStarted(name);

  // The controller's half of a frame, when its observation is delivered.
  const auto deliver = [&](double t_cmd, Processed& p) {
    if (timer) timer->resume(p.index);
    const control::TargetObservation& obs = p.obs;
    const double tc = p.frame.capture_time;
    const bool had_track = ours != nullptr && ours->filter().initialized();
    const std::size_t reacquisitions = ours != nullptr ? ours->reacquisitions() : 0;
    std::optional<tracking::PlanarTargetFilter::Kinematics> prior;  // x(k|k−1), for the innovation record
    if (tel != nullptr && had_track && obs.detected) prior = ours->filter().at(obs.stamp);
    ctrl->observe(obs);

    bool used = obs.detected;  // the baseline uses every detection
    Vector2d filt = Vector2d::Constant(std::nan(""));
    if (ours != nullptr && obs.detected) {
      const tracking::PlanarTargetFilter::Update& u = ours->lastUpdate();
      const bool started = !had_track || ours->reacquisitions() != reacquisitions;
      const tracking::GateDecision d = decisionOf(u, started);
      score.decision(d);
      used = u.accepted;
      if (has_truth && (d == tracking::GateDecision::Accept || d == tracking::GateDecision::Reject)) {
        // NIS of every tested measurement; NEES of x(k|k) when it was fused (the path knows v).
        const estimation::StateEstimate& est = ours->filter().estimate();
        Eigen::Vector4d truth;
        truth << p.truth.plane, world.path().velocity(tc);
        score.consistency(tc, u.nis, d == tracking::GateDecision::Accept, est.x().head<4>(),
                          est.P().topLeftCorner<4, 4>(), truth);
      }
      // The filtered estimate scored on every detected frame: a measurement the gate rejected
      // still counts, with the filter's own estimate at that time (its prediction).
      if (ours->filter().initialized())
        filt = u.accepted ? ours->filteredPlane() : Vector2d(ours->filter().at(obs.stamp).p);
      if (tel != nullptr) {
        runtime::InnovationRecord r;
        r.channel = name;
        r.t = obs.stamp;
        r.id = p.index + 1;
        r.rows = 2;
        r.decision = d;
        if (d != tracking::GateDecision::Start && prior) {
          r.innovation = vec(obs.plane - prior->p);
          r.S = prior->P_pos + obs.plane_cov;
          r.nis = u.nis;
        }
        tel->innovation(r);
        const tracking::PlanarTargetFilter::Kinematics k = ours->filter().at(obs.stamp);
        Eigen::VectorXd x(4);
        x << k.p, k.v;
        tel->estimate({name, obs.stamp, x, k.P_pos});
      }
    }
    score.frame(tc, p.truth.error_px, obs.detected, obs.plane, p.truth.plane, used, filt);

    // The command, issued after the processing delay.
    control::ControlInput in;
    in.t = t_cmd;
    in.joints = unit.read(t_cmd);
    in.recent = recent.all();
    in.period = period;
    const control::ControlOutput out = ctrl->command(in);
    const robots::JointState e = robots::predictJointState(limits, in.joints, recent.all(), latency, t_cmd + latency);
    const bool safe = robots::isSafeCommand(limits, e.q, e.qdot, out.qdot, period, 1e-9);
    score.command(limits, in.joints.q, out.qdot, safe, out.mode == control::TrackingMode::Searching);
    if (const auto sent = pan_tilt::commandThroughFaults(unit, faults, t_cmd, out.qdot)) recent.issued(t_cmd, *sent);
    if (tel != nullptr) tel->command({name, t_cmd, vec(out.qdot)});

    if (io.frames != nullptr) {
      pan_tilt::FrameRecord r;
      r.controller = name;
      r.image = &p.frame.image;
      r.t = tc;
      r.truth = p.truth.plane;
      r.detected = obs.detected;
      r.measured = obs.plane;
      r.filtered = filt;
      r.truth_px = p.truth.px;
      r.measured_px = p.meas_px;
      r.has_prediction = out.has_prediction;
      r.predicted_px = out.has_prediction ? model_cam.normalizedToPixel(out.predicted_feature)
                                          : Vector2d::Constant(std::nan(""));
      r.principal_px = world.principal();
      r.error_px = p.truth.error_px;
      r.q = in.joints.q;
      r.qdot = in.joints.qdot;
      r.command = out.qdot;
      r.mode = static_cast<int>(out.mode);
      r.mode_name = control::toString(out.mode);
      if (timer) r.live_status = runtime::liveStatus(*live, *timer);
      io.frames->frame(r);
    }
    if (timer) timer->finish(p.index);
    if (io.progress && (p.index % 30 == 0 || p.index + 1 == n_frames))
      io.progress(static_cast<double>(p.index + 1) / static_cast<double>(n_frames));
  };

  runtime::Scheduler sched;
  sched.setPacing(hardware && !io.pacing.paced() ? runtime::Pacing{1.0} : io.pacing);
  std::size_t grabbed = 0;
  // The detector's last pixel: it looks around it first (a window instead of the whole frame; the same
  // detection whenever the disc is inside it, else the full frame: screen_target_detector.h).
  std::optional<Vector2d> last_detected_px;
  // The camera's half of a frame: grab, detect, measure, and send the observation on.
  std::function<void(double)> capture = [&](double) {
    const std::size_t k = grabbed++;
    std::optional<runtime::Frame> frame = source.grab();
    if (frame && faults.missesDeadline(*frame)) {  // stale: dropped as a lost frame (faults.h)
      faults.note("frames_late_dropped");
      frame.reset();
    }
    if (frame && stale.repeats(*frame)) {  // a frozen camera's old image with a new stamp (stale_frames.h)
      faults.note("frames_frozen_dropped");
      frame.reset();
    }
    if (frame) {
      if (timer) timer->resume(k);
      Processed p;
      p.index = k;
      const double tc = frame->capture_time;
      score.frameCaptured();
      if (!external) {
        p.truth = world.truth(renderer.lastCamera(), tc);
      } else if (has_truth) {
        const auto values = recorded->truth(frame->camera, frame->sequence);
        if (!values)
          throw core::InvalidInput("recording " + recorded->dir() + ": no truth for frame " + std::to_string(frame->sequence));
        p.truth = truthFromValues(*values);
      } else {
        p.truth = noTruth();
      }
      if (writer && has_truth)
        writer->truth(frame->camera, frame->sequence,
                      {p.truth.plane.x(), p.truth.plane.y(), p.truth.px.x(), p.truth.px.y(), p.truth.error_px});
      // [T] noise draws happen every frame (same sequence for both controllers).
      const Vector2d n = world.drawNoise();
      control::TargetObservation& obs = p.obs;
      obs.stamp = frame->stamp;
      const auto det = runtime::guardedDetect(faults, frame->camera, tc,
                                              [&] { return detector.detect(frame->image, frame->stamp, last_detected_px); });
      last_detected_px.reset();
      if (det && det->ok()) last_detected_px = det->value().pixel;
      std::optional<Vector2d> det_px;
      if (det && det->ok())
        det_px = faults.detected(frame->camera, tc, det->value().pixel, frame->image.cols, frame->image.rows);
      if (det_px && !runtime::usablePixel(*det_px, frame->image.cols, frame->image.rows)) {
        faults.note("detections_rejected");
        det_px.reset();
      }
      // The camera as the controllers know it at the capture stamp: calibrated intrinsics,
      // calibrated mount, encoder reading at the stamp.
      const robots::JointState joints = unit.read(frame->stamp);
      model_cam.c_M_w = kin_model.c_M_f(joints.q);
      if (writer)
        writer->tableRow(kPtuTable, frame->camera, frame->sequence,
                         {joints.t, joints.q.x(), joints.q.y(), n.x(), n.y(), world.R()(0, 0), world.R()(0, 1), world.R()(1, 1)});
      if (det_px) {
        // Back-project onto the screen plane (z_screen = 0) through that camera.
        if (const auto m = measureOnScreen(model_cam, *det_px, world.f_M_screen(), n)) {
          const Vector3d& meas_c = m->in_camera;
          obs.detected = meas_c.z() > 0.0;
          obs.plane = m->plane;
          obs.plane_cov = world.R();
          obs.feature = Vector2d(meas_c.x() / meas_c.z(), meas_c.y() / meas_c.z());
          p.meas_px = model_cam.normalizedToPixel(obs.feature);
          score.detectorError(tc, *det_px, p.truth.px);
        }
      }
      if (tel != nullptr) {
        tel->measurement({truthChannel(name), tc, k + 1, vec(p.truth.plane), {}});
        tel->scalar({imageErrorChannel(name), tc, p.truth.error_px});
        if (obs.detected) tel->measurement({name, obs.stamp, k + 1, vec(obs.plane), vec(world.sigma())});
      }
      const double t_cmd = tc + cfg.processing_delay;
      p.frame = std::move(*frame);
      to_controller.send(t_cmd, std::move(p));
      sched.at(t_cmd, runtime::priority::Control, [&](double t) {
        to_controller.receive(t, [&](double t_available, Processed& q) { deliver(t_available, q); });
        if (io.frames != nullptr && io.frames->quitRequested()) sched.requestStop();
      });
      if (timer) timer->pause(k);  // until its control event
    }
    // The run's duration (the renderer ends there by itself); a live source's dropped frames count.
    if ((live ? live->delivered() : grabbed) >= n_frames) return;
    if (const auto next = source.nextReadyTime()) sched.at(*next, runtime::priority::Capture, capture);
  };
  if (const auto first = source.nextReadyTime()) sched.at(*first, runtime::priority::Capture, capture);
  while (!sched.stopRequested() && sched.step()) {
  }
  if (hardware) {
    hardware->halt();
  } else {
    world.unit().stop(world.unit().now().t);
    world.unit().advanceTo(world.unit().now().t + 1.0);
  }

  const double wall =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - wall0).count();
  if (writer) writer->finish();
  PanTiltRunMetrics m = score.finish(ours, world.unit(), wall);
  m.stopped = sched.stopRequested();
  m.scored = has_truth;
  if (!faults.empty()) m.faults = faults.report();
  if (live) m.live = runtime::liveReport(*live, *timer, "one frame period at " + fpsText(cfg.fps) + " fps");
  return m;
}

PanTiltComparison runPanTiltComparison(const PanTiltScenarioConfig& config, std::uint64_t seed, const PanTiltRunIo& io) {
  PanTiltComparison c;
  c.seed = seed;
  c.path = pathShapeName(config.path.shape);
  const double share = config.run_baseline ? 0.5 : 1.0;
  PanTiltRunIo part = io;
  if (io.progress) part.progress = [&](double f) { io.progress(share * f); };
  c.ours = runPanTilt(config, seed, PanTiltControllerKind::Predictive, part);
  if (config.run_baseline && !c.ours.stopped) {
    if (io.progress) part.progress = [&](double f) { io.progress(0.5 + 0.5 * f); };
    c.baseline = runPanTilt(config, seed, PanTiltControllerKind::Baseline, part);
    c.has_baseline = true;
  }
  return c;
}

}  // namespace viewline::scenarios
