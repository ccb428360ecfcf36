#include "viewline/scenarios/mobile_capture/loop.h"

#include <Eigen/Cholesky>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>

#include "viewline/core/interrupt.h"
#include "viewline/robots/mobile_ground_localization.h"
#include "viewline/scenarios/mobile_capture/chase.h"
#include "viewline/scenarios/mobile_capture/recording.h"
#include "viewline/scenarios/mobile_capture/robot_link.h"
#include "viewline/scenarios/mobile_capture/world.h"

namespace viewline::scenarios {

using Eigen::Vector2d;
using Eigen::Vector3d;
using Eigen::VectorXd;
using namespace mobile_capture;

namespace {

// Tie order at one control tick: the gripper acts on the estimate of the previous frame, then
// this instant's frame is grabbed and processed, then the base and head laws use it and the
// plant advances over the period.
constexpr int kGrasp = runtime::priority::Control;
constexpr int kVision = runtime::priority::Capture;
constexpr int kDrive = runtime::priority::Capture + 1;

/// f(i, t) at the ticks i = first, first + stride, ... <= clock.last, each event scheduling the
/// next at clock.time(i) (a product, as the hand loop computed it, so that every time stamp stays
/// bit for bit what it was; Scheduler::every would accumulate t += period instead).
class Ticks {
public:
  using Action = std::function<void(long i, double t)>;
  Ticks(runtime::Scheduler& s, TickClock clock, long stride, int priority, Action f)
      : s_(s), clock_(clock), stride_(stride), priority_(priority), f_(std::move(f)) {}
  void start(long first) {
    if (first > clock_.last) return;
    s_.at(clock_.time(first), priority_, [this, first](double t) {
      f_(first, t);
      start(first + stride_);
    });
  }

private:
  runtime::Scheduler& s_;
  TickClock clock_;
  long stride_;
  int priority_;
  Action f_;
};

Eigen::VectorXd vec(std::initializer_list<double> v) {
  Eigen::VectorXd x(static_cast<Eigen::Index>(v.size()));
  Eigen::Index i = 0;
  for (double d : v) x[i++] = d;
  return x;
}

}  // namespace

// ------------------------------------------------------------------------------------------------
// Oracle: the same planner, base law, robot and capture rule fed the object's true position and
// true future path.

OracleResult runOracle(const MobileCaptureConfig& cfg, std::uint64_t seed) {
  cfg.validate();
  Streams rng(seed);
  const sim::GroundTarget target(targetParams(cfg, sim::GroundProfile::Capture, targetDuration(cfg)), rng.object);
  RobotSim robot(cfg);
  const TickClock clock = TickClock::of(cfg);
  runtime::Scheduler sched;
  OracleResult result{false, cfg.max_time};
  planning::CapturePlan plan;
  Ticks capture(sched, clock, 1, kGrasp, [&](long, double t) {
    const auto s = target.state(t);
    if (cfg.trigger.contains(toRobot(robot.base.pose(), Vector2d(s.x, s.y)))) {
      result = {true, t};
      sched.requestStop();
    }
  });
  Ticks planner(sched, clock, TickClock::visionEvery(cfg), kVision, [&](long, double t) {
    const auto& p = robot.base.pose();
    plan = planning::planCapture(truePath(target, t, cfg.vision_period, cfg.horizon_steps), {{p.x, p.y}, p.theta},
                                 cfg.plannerParams());
  });
  Ticks drive(sched, clock, 1, kDrive, [&](long, double) {
    const control::BaseCommand c = control::goToPoint(robot.base.pose(), plan.point, cfg.goParams());
    robot.base.setCommand(c.v, c.omega);
    robot.base.step(rng.drive);
  });
  capture.start(0);
  planner.start(0);
  drive.start(0);
  sched.runUntil(clock.time(clock.last));
  return result;
}

// ------------------------------------------------------------------------------------------------
// Our loop.

MobileCaptureRun runMobileCapture(const MobileCaptureConfig& cfg, std::uint64_t seed, const MobileCaptureHooks* hooks) {
  cfg.validate();
  MobileCaptureRun run;
  run.seed = seed;
  Streams rng(seed);
  const sim::GroundTarget target(targetParams(cfg, sim::GroundProfile::Capture, targetDuration(cfg)), rng.object);
  RobotSim robot(cfg);
  // The head camera: the renderer, or a recorded run (recording.h), recorded when asked.
  const std::string replay_dir = hooks ? hooks->replay_dir : std::string();
  const auto camera_pose = [&] {
    const robots::BasePose& p = robot.base.pose();
    return trueCamera_c_M_w(robot.head, robot.q, p.x, p.y, p.theta);
  };
  std::unique_ptr<MobileCaptureFrames> head_frames =
      replay_dir.empty() ? std::make_unique<MobileCaptureFrames>(cfg, target, rng, camera_pose)
                         : std::make_unique<MobileCaptureFrames>(replay_dir, target);
  if (hooks && !hooks->record_dir.empty())
    head_frames->record(hooks->record_dir, estimatorCamera(cfg), [&] { return robot.reading(); });
  MobileCaptureFrames& source = *head_frames;
  runtime::FaultPlan faults(cfg.faults, core::deriveSeed(seed, 0xFA));
  runtime::FrameSource& frames = faults.wrap(source);
  RobotLink link(robot, faults);  // commands through the robot faults (robot_link.h)
  // The chase's perception and commands, shared with the footage session (chase.h).
  ChaseController chase(cfg);
  const tracking::UnicycleTracker& track = chase.track();
  core::Camera camera = estimatorCamera(cfg);  // detection ROI, ground localisation
  const robots::AnglePerPixel printed{cfg.hfov, cfg.vfov, robots::AngleRange::PrintedSlant};
  const robots::AnglePerPixel horizontal{cfg.hfov, cfg.vfov, robots::AngleRange::Horizontal};
  const double plane_z = chase.planeZ();
  runtime::TelemetrySink* sink = hooks ? hooks->telemetry : nullptr;

  Eigen::Matrix2d bias_cov = Eigen::Matrix2d::Zero();  // m², B of the last detection (floorMeasurement)
  double track_since = -1.0, next_nees = -1.0;  // s: start of the live track; time of the next NEES sample
  double first_seen = -1.0, last_grasp = -1e9;

  const TickClock clock = TickClock::of(cfg);
  runtime::Scheduler sched;
  if (hooks) sched.setPacing(hooks->pacing);

  // Grasp: when the estimate lies in the trigger zone the gripper closes; it holds the object
  // when the true object lies in the jaws.
  Ticks grasp(sched, clock, 1, kGrasp, [&](long, double t) {
    const robots::BasePose pose = robot.base.pose();
    if (!track.valid() || t - last_grasp < cfg.grasp_cooldown ||
        !cfg.trigger.contains(toRobot(pose, track.positionAt(t))))
      return;
    ++run.grasp_attempts;
    last_grasp = t;
    const auto truth = target.state(t);
    if (cfg.jaws.contains(toRobot(pose, Vector2d(truth.x, truth.y)))) {
      run.captured = true;
      run.capture_time = t;
      sched.requestStop();
    }
  });

  // Vision: detection, ground back-projection, track update, prediction, plan.
  auto process = [&](const runtime::Frame& frame) {
    const double t = frame.stamp;
    ++run.frames;
    const auto truth = target.state(t);
    const Vector2d obj(truth.x, truth.y);
    // The estimators' camera from odometry and the joint encoders at the frame's time (the reading
    // a recording keeps for this frame in head.csv: recording.h).
    const HeadReading reading = robot.reading();
    const robots::BasePose pose = reading.base;
    camera.c_M_w = estimatorCamera_c_M_w(cfg, robot.head, reading);
    // The track is settled (its NIS counts) once it has lived kConsistencySettle s before this update.
    const bool settled = track.valid() && t - track_since >= kConsistencySettle;
    const double seen_before = chase.lastSeen();
    const ChaseObservation o = chase.frame(faults, frame, camera, pose);
    bool detected = false, fused = false;
    std::optional<FloorMeasurement> measurement;
    double nis = std::numeric_limits<double>::quiet_NaN();
    Vector2d pixel = Vector2d::Zero();
    if (o.pixel) {
      pixel = *o.pixel;
      if (sink) sink->measurement({channel::kPixel, t, frame.sequence, pixel, vec({cfg.pixel_sigma, cfg.pixel_sigma})});
      if (o.floor) {
        const Vector2d& exact = o.floor->z;
        detected = true;
        ++run.detections;
        if (seen_before >= 0.0) run.longest_lost = std::max(run.longest_lost, t - seen_before);
        if (first_seen < 0.0) first_seen = t;
        const auto a = robots::groundPointAnglePerPixel(camera, pixel, printed, plane_z);
        const auto h = robots::groundPointAnglePerPixel(camera, pixel, horizontal, plane_z);
        if (a && h) {
          run.localization.sse_exact += (exact - obj).squaredNorm();
          run.localization.sse_printed += (*a - obj).squaredNorm();
          run.localization.sse_horizontal += (*h - obj).squaredNorm();
          ++run.localization.count;
        }
        bias_cov = o.floor->bias_cov;
        measurement = *o.floor;
        const tracking::UnicycleUpdate& u = *o.update;
        fused = u.fused;
        nis = u.report.nis;
        if (settled && std::isfinite(nis)) {
          run.nis_sum += nis;
          ++run.nis_count;
        }
        if (sink) {
          const double nan = std::numeric_limits<double>::quiet_NaN();
          sink->measurement({channel::kFloor, t, frame.sequence, exact, o.R.diagonal().cwiseSqrt()});
          sink->measurement({channel::kFloorAnglePerPixel, t, frame.sequence,
                             vec({a ? a->x() : nan, a ? a->y() : nan, h ? h->x() : nan, h ? h->y() : nan}),
                             {}});
          if (u.decision) {
            sink->innovation({channel::kObject, t, frame.sequence, 0, 2, u.report.innovation, u.report.S, u.report.nis,
                              *u.decision});
          }
        }
      }
    }
    if (!track.valid()) {
      track_since = -1.0;
    } else if (track_since < 0.0) {
      track_since = t;
    } else if (t - track_since >= kConsistencySettle && t >= next_nees) {
      Eigen::Matrix2d P = track.state().P().topLeftCorner<2, 2>();
      P += bias_cov;
      const Vector2d e = track.state().x().head<2>() - obj;
      run.nees_sum += e.dot(P.ldlt().solve(e));
      ++run.nees_count;
      next_nees = t + kNeesSpacing;
    }
    if (sink) {
      sink->estimate({channel::kTruthObject, t, vec({truth.x, truth.y, truth.theta, truth.v, truth.omega}), {}});
      sink->estimate({channel::kTruthRobot, t, vec({pose.x, pose.y, pose.theta, robot.q.tilt, robot.q.pan}), {}});
      if (track.valid()) {
        // The object p = s − b: the bias b (independent of the track's error, never observed by it)
        // adds its covariance to the position block (Schmidt's consider covariance of an
        // unobservable bias state, zero gain).
        Eigen::MatrixXd P = track.state().P();
        P.topLeftCorner<2, 2>() += bias_cov;
        sink->estimate({channel::kObject, t, track.state().x(), P});
      }
      const planning::CapturePlan& plan = chase.plan();
      sink->command({channel::kPlan, t,
                     vec({plan.reachable ? 1.0 : 0.0, static_cast<double>(plan.steps), plan.point.x(), plan.point.y(),
                          static_cast<double>(static_cast<int>(chase.mode()))})});
    }
    if (hooks && hooks->on_frame) {
      MobileCaptureFrame f;
      f.t = t;
      f.image = &frame.image;
      f.detected = detected;
      f.pixel = pixel;
      f.robot = pose;
      f.joints = robot.q;
      f.object_true = obj;
      f.fused = fused;
      f.measurement = measurement;
      f.bias_cov = bias_cov;
      f.nis = nis;
      f.estimate_valid = track.valid();
      if (track.valid()) f.estimate = track.state().x();
      f.prediction = chase.prediction();
      f.plan = chase.plan();
      f.mode = chase.mode();
      hooks->on_frame(f);
    }
    if (hooks && hooks->quit_requested && hooks->quit_requested()) {
      run.interrupted = true;
      sched.requestStop();
    }
  };
  // Frames when the source has them (a renderer: every vision period, on the control ticks).
  FrameScreen screen;  // late, frozen and stale-stamp frames dropped (chase.h)
  std::function<void()> next_frame = [&] {
    const auto t = frames.nextReadyTime();
    if (!t) return;
    sched.at(*t, kVision, [&](double) {
      if (auto frame = frames.grab()) {
        if (screen.admit(faults, *frame)) process(*frame);
      }
      next_frame();
    });
  };

  // Control: base law to the capture point and head towards the prediction, or the search.
  Ticks drive(sched, clock, 1, kDrive, [&](long, double t) {
    const robots::BasePose pose = robot.base.pose();
    const ChaseCommand c = chase.command(t, pose, robot.head, robot.q, robot.base.turnRate());
    const control::BaseCommand& cmd = c.base;
    const robots::PanTiltJoints& head_target = c.head;
    link.send(t, cmd, head_target);
    robot.base.step(rng.drive);
    if (sink) {
      sink->command({channel::kBase, t, vec({cmd.v, cmd.omega})});
      sink->command({channel::kHead, t, vec({head_target.tilt, head_target.pan})});
    }
  });

  grasp.start(0);
  next_frame();
  drive.start(0);
  sched.runUntil(clock.time(clock.last));
  if (!run.captured) run.capture_time = cfg.max_time;
  run.gate = track.gate().counts();
  if (!faults.empty()) run.faults = faults.report();
  if (sink) sink->flush();
  // requestStop() also ends a run at its capture; a signal or the view's quit ends it early.
  if (core::interruptRequested()) run.interrupted = true;
  if (!run.interrupted) source.finishRecording();
  if (run.interrupted) return run;

  const OracleResult oracle = runOracle(cfg, seed);
  run.oracle_captured = oracle.captured;
  run.oracle_time = oracle.time;
  return run;
}

}  // namespace viewline::scenarios
