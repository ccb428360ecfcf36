#pragma once
// Mobile-capture scenario (SPEC §4, [K]): a differential-drive robot with a pan/tilt
// camera chases a red 8x6 cm object that moves on the floor with [K]'s speed and turn-rate
// profiles, and grasps it with a front gripper.
//
// One run (runMobileCapture) on one runtime::Scheduler, simulation time t in s, world frame z up,
// floor z = 0; every time stamp is i · control_period for the control tick i, and at one tick the
// grasp check runs first, then the frame of that instant, then the control laws:
//   every control period (10 ms): wheel PID + motors (robots::DifferentialDrive), head joints
//     (rate-limited servo to the set point), base law to the capture point (control::goToPoint),
//     head set point = IK towards the filter's prediction of the object at the next tick;
//   every vision period (100 ms): a frame from the head camera's runtime::FrameSource (here
//     mobile_capture::RenderedHeadCamera: sim::GroundWorld, sim::Renderer, sensor noise), the
//     red blob is detected (vision::BallDetector with a red HSV range, contour centroid), its
//     pixel back-projected onto the plane of the object's centre (robots::groundPointExact with
//     the camera pose from odometry and the joint encoders), the track (tracking::UnicycleTracker:
//     EKF on estimation::UnicycleModel, gated by tracking::TrackGate) is updated, the
//     least-squares predictor (estimation::UnicycleTrajectoryPredictor) rolls the path forward
//     M steps and the capture point is replanned ([K] eq 30, planning::planCapture);
//   lost target: control::SearchPattern (look at the prediction, then sweep; base turns).
//   Grasp: when the *estimated* object lies in the gripper's trigger zone, the gripper closes;
//   the grasp succeeds when the *true* object lies in the jaw zone (robot frame), else the
//   attempt is counted and the chase goes on.
//
// Oracle (same seed, same object path): the same planner, base law, robot and grasp rule, fed
// the object's true current position and true future path (no camera, no filter).
// capture_time_ratio_to_oracle = our capture time / the oracle's.
//
// [K]'s profiles (sim::GroundTarget): k is the index of the 100 ms vision/filter step
// (t = 0.1 k s); v in cm/s, ω in rad/s; ξv, ξω are drawn once per step k, independent, with
// variances in (cm/s)² and (rad/s)²: Capture 2 and 0.1, FilterTest 3 and 0.1. The filter test's
// measurement noise variance 2 is in cm² per axis of the measured floor position.
//
// Filter test ([K] §3.2, runFilterTest): the FilterTest profile, positions measured every 100 ms
// with that noise (no images), the same track; errors of θ, v, ω over time and their RMSE after a
// convergence time, against the true (noisy) inputs and against the nominal profile.
//
// Camera parameters. Inline camera keys (width, height, hfov_deg, vfov_deg): one
// perfect pinhole camera renders and estimates. With `rig: <folder>` (calib/rigs/mobile): the
// renderer uses the TRUE head camera of truth.yaml (intrinsics with barrel distortion) on the
// true head (the DH chain of robots::MobilePanTilt: truth.yaml's pose is that chain at a rest
// joint position q0, found and checked at load), and every estimator uses the CALIBRATED camera:
// rig.yaml's intrinsics, and a pose from the camera-to-ground calibration taken at q0
// (rig.yaml's c_M_w = ground.yaml's c_M_g placed at the surveyed board spot). The calibrated pose
// differs from the DH camera at q0 by a fixed correction of the camera on its mount,
//   c'_M_c = c_M_w_cal · c_M_w_DH(q0)⁻¹,
// so the estimators' camera at joints q and base pose b is  c'_M_w(q, b) = c'_M_c · c_M_w_DH(q, b).
// The angle-per-pixel method then uses the calibrated fields of view (2 atan(W / 2 px), ...).
//
// Ground localisation: every detection is also located with [K]'s angle-per-pixel formula
// (printed slant range and corrected horizontal range); errors against the true object centre.
// compareGroundLocalization additionally sweeps the field of view with projected floor points.

// Telemetry (MobileCaptureHooks::telemetry): measurements (pixel, floor point, [K]'s floor
// points), the track's innovations with their gate decision, its estimates, the truth, the plan
// and the base and head commands (channels in mobile_capture::channel); a display or the tuning
// tool also gets every frame (MobileCaptureHooks::on_frame).
//
// Files: mobile_capture/config (parameters, reader), world (object, floor, robot, head camera
// source), loop (the chase and the oracle), metrics (filter test, sweep, batch, summary),
// recording (record and replay), robot_link (the base's command link and its faults), footage
// (one session over a camera's footage with the robot held at its start pose, no truth).

#include "viewline/scenarios/mobile_capture/config.h"
#include "viewline/scenarios/mobile_capture/loop.h"
#include "viewline/scenarios/mobile_capture/metrics.h"
