#include "pan_tilt_recording.h"

#include <filesystem>
#include <optional>

#include "viewline/core/error.h"
#include "viewline/runtime/recording.h"
#include "viewline/scenarios/pan_tilt/loop.h"
#include "viewline/scenarios/pan_tilt/world.h"
#include "viewline/vision/screen_target_detector.h"

namespace viewline::tuning::detail {

namespace fs = std::filesystem;

namespace {

/// The folder holding recording.csv: `dir` itself or its predictive/ subfolder (--record DIR).
std::string recordingFolder(const std::string& dir) {
  if (fs::exists(fs::path(dir) / "recording.csv")) return dir;
  const fs::path ours = fs::path(dir) / "predictive";
  if (fs::exists(ours / "recording.csv")) return ours.string();
  throw core::InvalidInput(dir + ": not a recording (no recording.csv, nor predictive/recording.csv as "
                           "pan_tilt_tracking --record DIR writes)");
}

}  // namespace

PanTiltRecordedMeasurements panTiltRecordedMeasurements(const scenarios::PanTiltScenarioConfig& cfg,
                                                         const std::string& dir) {
  using Eigen::Vector2d;
  PanTiltRecordedMeasurements out;
  out.dir = recordingFolder(dir);
  runtime::RecordingSource source(out.dir);
  out.grabs = source.entries().size();
  const std::string ptu_file = out.dir + "/" + scenarios::kPtuTable + ".csv";
  const std::optional<runtime::RecordingTruth> ptu = source.table(scenarios::kPtuTable);
  if (!ptu)
    throw core::InvalidInput(out.dir + ": no " + std::string(scenarios::kPtuTable) +
                             ".csv (the unit's joint readings per frame, which pan_tilt_tracking --record writes): "
                             "without them a detection cannot be placed on the screen");
  if (ptu->columns != scenarios::ptuTableColumns())
    throw core::InvalidInput(ptu_file + ": unexpected columns (expected camera,sequence then those of "
                             "scenarios::ptuTableColumns())");

  // The loop's geometry, all from the config (calibrated camera and mount, screen pose): none of it
  // depends on a seed.
  core::Camera cam = scenarios::panTiltModelCamera(cfg);
  const robots::PanTiltKinematics kin =
      cfg.calibrated_e_M_c ? robots::PanTiltKinematics(*cfg.calibrated_e_M_c) : robots::PanTiltKinematics();
  const Eigen::Isometry3d f_M_screen = scenarios::pan_tilt::screenPose(cfg);
  vision::ScreenTargetDetector detector(cfg.detector);

  bool have_R = false;
  while (source.nextReadyTime()) {
    const std::optional<runtime::Frame> frame = source.grab();
    if (!frame) continue;  // a lost grab: no measurement, as in the loop
    const auto row = ptu->rows.find({frame->camera, frame->sequence});
    if (row == ptu->rows.end())
      throw core::InvalidInput(ptu_file + ": no row for camera " + std::to_string(frame->camera) + " sequence " +
                               std::to_string(frame->sequence) + " of recording.csv");
    const std::vector<double>& v = row->second;  // joint_t, pan, tilt, noise_x, noise_y, R_xx, R_xy, R_yy
    Eigen::Matrix2d R;
    R << v[5], v[6], v[6], v[7];
    if (!have_R) {
      out.R = R;
      have_R = true;
    } else if (R != out.R) {
      throw core::InvalidInput(ptu_file + ": R changes at camera " + std::to_string(frame->camera) + " sequence " +
                               std::to_string(frame->sequence) + " (the replayed filter takes one R per recording)");
    }
    PanTiltRecordedFrame f;
    f.t = frame->stamp;
    const Vector2d n(v[3], v[4]);
    // The capture step of the pan-tilt loop (scenarios::measureOnScreen): the camera at the recorded
    // joint reading, the detection's ray cut with the screen plane, [T]'s noise added, and the
    // measurement kept only in front of the camera.
    cam.c_M_w = kin.c_M_f(Vector2d(v[1], v[2]));
    const auto det = detector.detect(frame->image, frame->stamp);
    if (det.ok()) {
      if (const auto m = scenarios::measureOnScreen(cam, det.value().pixel, f_M_screen, n)) {
        f.detected = m->in_camera.z() > 0.0;
        f.z = m->plane;
      }
    }
    out.frames.push_back(f);
  }
  if (!have_R) throw core::InvalidInput(out.dir + ": no frame to replay");
  if (!(out.frames.back().t - out.frames.front().t > cfg.metrics_start))
    throw core::InvalidInput(out.dir + ": " + std::to_string(out.frames.size()) + " frames end before run.metrics_start (" +
                             std::to_string(cfg.metrics_start) + " s)");
  return out;
}

}  // namespace viewline::tuning::detail
