#pragma once
// The table-ball balancing scenario ([M], SPEC §3) as library code: one call runs the closed
// loop (world physics, rendering, detection, observer, controller, metrics) for a plain config
// and a seed, so the app and the tuning tool run exactly the same code. Its parts, each in its
// own file under modules/scenarios/table_ball/: config (the struct and its YAML reader), world
// (physics, wrist, head camera as a frame source), loop (the scheduler's events) and metrics.
// On footage (source: images, video or v4l2) footage.h runs one session without truth instead.
//
// World (SI, world z up): a robot arm holds a square table (red, raised black borders) of side
// L = 0.3 m whose untilted centre is at `table.center`; a green ball (r = 0.025 m) rolls on it
// without slipping (sim::TiltTable: a = (5/7)[t_R_w g]_xy, inelastic borders). The table's two
// tilt angles are driven by the wrist (robots::SimulatedTableTilt: delay, rate and angle
// limits). A head camera (320x240, 90° horizontal FOV: fx = fy = 160, cx = 160, cy = 120, no
// distortion, 50 fps) looks at the table from `camera.position` towards `camera.look_at` and
// sways slightly like a head (rotation amplitude `sway_deg`, translation `sway_translation`,
// incommensurate frequencies around `sway_hz`); its rotation to the ground is known to the
// observer (with optional noise `ground_rotation_noise_deg`, as from an IMU or the neck joints).
// Frames are rendered by sim::CameraRig (sensor noise, motion blur, dropped frames).
//
// Camera parameters. Inline camera keys (width, height, hfov_deg, cx, cy, position, look_at):
// the renderer and the observer share one perfect camera. With `rig: <folder>` (a default
// simulated rig, calib/rigs/table): the renderer uses the TRUE head camera of truth.yaml
// (intrinsics, distortion, rest pose) and the observer the CALIBRATED one: rig.yaml's intrinsics,
// and its rest-pose rotation to the ground from ground.yaml (g_R_c, camera-to-ground from floor
// board images). The head's sway is measured (neck joints / IMU), so the observer's camera at
// frame k is  c_M_w_obs(t) = D(t) · c_M_w_cal  with D(t) = c_M_w_true(t) · c_M_w_true(0)⁻¹ the true
// sway (plus the ground_rotation_noise); the calibration error stays in every frame.
//
// Loop timing (one 1 ms physics tick): frame k is captured at t_k (middle of the exposure),
// processed once the exposure is over, and the controller's tilt ramp starts at
// t_k + latency; the arm's trajectory interpolator sends the ramp to the wrist as 1 kHz
// position commands, and the wrist adds its delay. The controller's model delay is
// latency + wrist delay.
//
// Events: set-point changes (table frame, m) and pushes (an impulse on the ball: Δv, m/s).
//
// Metrics (position errors are 2-D Euclidean, in the table frame, truth at the capture time):
//   observer_rmse_mm        RMS |p̂ − p| over frames with an estimate after `warmup`
//   measurement_rmse_mm     RMS |y − p| over frames with a ball measurement after `warmup`
//   tuning comparison       the same RMSE for [M]'s two tunings (σw = 1, σv = 0.005 and
//                           σw = σv = 1) and the stationary-gain filter, all fed the same
//                           measurements (the loop itself runs on the configured filter)
//   per set-point step (|Δ| >= min_step): overshoot_pct = 100 · max over the window of the
//     position's excursion past the new set point along the step direction / |Δ|;
//     settling_time_s = time after the change until the stepped coordinate (p − ref)·Δ/|Δ| stays
//     within 2 % of |Δ| (the classic step-response definition); settling_time_2d_s: until |p − ref|
//     stays within max(2 % of |Δ|, settle_min_band = 2 mm), so it counts cross-axis errors too;
//     steady_state_error_mm = mean |p − ref| over the last `steady_window` s before the next
//     event. The summary reports the worst step.
//   push_recovery_s         time after a push until |p − ref| stays within `push_band`
//                           (worst push).
//   robot_faults            (only with robot_silent / robot_limit_error faults) per window:
//                           the largest |p − ref| from its start, the time from its end until
//                           |p − ref| stays within `push_band`, and whether the ball reached a
//                           border, up to the next event (scenarios/table_ball/wrist_link.h).
//   nis_sampled             the filter's NIS every `nis_spacing` s (2 dof; the measurement errors
//                           decorrelate within about 5 frames) against its two-sided 99 % band
//   nees_position_velocity  (p, v) error against the truth in units of the filter's covariance
//                           (4 dof) every `nees_spacing` s, against its band; a sample due in the
//                           frame of a push waits two frames (no image has shown the push yet).
//   frame_time_ratio_to_reference  mean per-frame cost of the observer (detection + filter)
//     divided by that of the plain OpenCV reference of [M]'s steps (vision::referenceTableScene,
//     full frame, fresh buffers) + the same filter step, both timed on every frame of the run
//     (wall clock, steady_clock). frame_cpu_ratio_to_reference: the same with the CPU time of the
//     calling thread (CLOCK_THREAD_CPUTIME_ID). On a loaded machine the wall ratio is dominated
//     by waiting for a core (the observer runs right after the long render and is preempted
//     more often than the reference after it); the CPU ratio is the cost itself. Both pipelines
//     run on the calling thread for a 320x240 image (OpenCV does not split such small images).

#include "viewline/scenarios/table_ball/config.h"
#include "viewline/scenarios/table_ball/footage.h"
#include "viewline/scenarios/table_ball/loop.h"
#include "viewline/scenarios/table_ball/metrics.h"
#include "viewline/scenarios/table_ball/world.h"
