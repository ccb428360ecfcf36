#pragma once
// A default simulated rig as a scenario uses it: the simulator renders with the TRUE
// cameras (calib/rigs/<rig>/truth.yaml) and every estimator uses the CALIBRATED cameras
// (calib/rigs/<rig>/rig.yaml, made by scripts/calibrate-default-rigs from rendered board images).
// So every scenario runs on imperfect parameters, as a real rig does.
//
// In a scenario config:
//   rig: ../calib/rigs/table        # folder, relative to the config file
//
//   const auto rig = scenarios::loadSimulatedRig(cfg, "rig");
//   renderer.setCamera(rig.trueCamera("head"));          // world -> pixels of the simulation
//   observer.setCamera(rig.calibratedCamera("head"));    // what the estimator believes
//
// Other files of a rig folder (ground.yaml, e_M_c.yaml) are read by the scenario that needs them:
// `file("ground.yaml")` gives their path.

#include <string>
#include <vector>

#include "viewline/calib/synthetic.h"
#include "viewline/core/camera.h"
#include "viewline/io/config.h"

namespace viewline::scenarios {

/// A calibrated rig folder: the true cameras the simulator renders with and the calibrated ones estimators use.
struct SimulatedRig {
  std::string folder;                    ///< the rig folder as resolved (no trailing slash)
  calib::RigTruth truth;                 ///< what the simulator renders with (and scores against)
  std::vector<core::Camera> calibrated;  ///< rig.yaml: what estimators use

  /// Throws core::InvalidInput naming the rig folder and the known camera names.
  const core::Camera& trueCamera(const std::string& name) const;
  /// The calibrated camera `name` (rig.yaml: intrinsics and c_M_w); throws like trueCamera.
  const core::Camera& calibratedCamera(const std::string& name) const;
  /// Path of another file of the rig folder.
  std::string file(const std::string& name) const;
};

/// Loads `<folder>/truth.yaml` and `<folder>/rig.yaml`. Both must list the same camera names with
/// the same image sizes; otherwise core::InvalidInput names the folder and what differs.
SimulatedRig loadSimulatedRig(const std::string& folder);
/// Same, with the folder read from `cfg.getPath(key)` (relative to the config file); errors in the
/// rig files are reported with the config's file:line:key in front.
SimulatedRig loadSimulatedRig(const io::ConfigNode& cfg, const std::string& key = "rig");

/// The calibrated camera-to-ground rotation g_R_c of a rig folder's ground.yaml (written by
/// calib's camera-to-ground for the table and mobile rigs; ground frame g: z up, x along the
/// floor board). The rig's world has no yaw with respect to g (scripts/calibrate-default-rigs puts
/// the board at yaw 0), so g_R_c must equal the calibrated camera's w_R_c in rig.yaml: checked
/// within 0.01°. Throws core::InvalidInput naming the file.
Eigen::Matrix3d loadGroundRotation(const SimulatedRig& rig, const std::string& camera_name);

}  // namespace viewline::scenarios
