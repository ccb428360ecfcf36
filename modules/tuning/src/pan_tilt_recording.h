#pragma once
// Tuning the pan-tilt filter on a recording of its frames (internal to modules/tuning): the
// measurements a recording gives, rebuilt without the unit, the simulator or a seed.
//
// The camera rides on the unit, so a detected pixel becomes a screen-plane measurement only through
// the unit's pose at that frame. pan_tilt_tracking --record writes, beside the frames, ptu.csv
// (scenarios::ptuTableColumns()): per frame the joint reading the loop used, [T]'s noise draw it
// added and the R it gave the filter, from a simulated unit or a FLIR PTU alike. A replay runs each
// recorded frame through the scenario's detector (ScreenTargetDetector, the config's detector
// settings) and back-projects the detection onto the screen plane through the calibrated camera
// and mount (panTiltModelCamera, calibration.e_M_c) at the recorded joints, as the loop does
// (modules/scenarios/pan_tilt/loop.cpp, the capture step): the same measurements, bit for bit,
// whatever filter or controller drove the unit while recording. Those measurements are then
// replayed open loop through the filter for each candidate noise.

#include <cstddef>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "viewline/scenarios/pan_tilt/config.h"

namespace viewline::tuning::detail {

/// One grabbed frame of a pan-tilt recording as the filter sees it.
struct PanTiltRecordedFrame {
  double t = 0.0;         ///< the frame's stamp, s (the measurement's time)
  bool detected = false;  ///< a detection that back-projected in front of the camera
  Eigen::Vector2d z = Eigen::Vector2d::Zero();  ///< screen-plane measurement (m), valid when detected
};

/// The measurements of a pan-tilt recording.
struct PanTiltRecordedMeasurements {
  std::string dir;                               ///< the folder holding recording.csv
  std::size_t grabs = 0;                         ///< grabs in the recording (lost ones included)
  std::vector<PanTiltRecordedFrame> frames;      ///< every frame the recording holds, in grab order
  Eigen::Matrix2d R = Eigen::Matrix2d::Identity();  ///< the measurement covariance the loop gave the filter, m²
};

/// The measurements of the recording in `dir` (a folder with recording.csv and ptu.csv, or the
/// folder given to pan_tilt_tracking --record, whose predictive/ subfolder holds them) through the
/// detector and geometry of `config`. Throws core::InvalidInput naming the folder or file (no
/// recording, no ptu.csv, a frame without its ptu.csv row, R that changes along the recording,
/// too short for run.metrics_start).
PanTiltRecordedMeasurements panTiltRecordedMeasurements(const scenarios::PanTiltScenarioConfig& config,
                                                         const std::string& dir);

}  // namespace viewline::tuning::detail
