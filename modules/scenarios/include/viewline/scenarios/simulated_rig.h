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
//
// A real rig is only calibrated: its folder has rig.yaml (and e_M_c.yaml / ground.yaml where the
// scenario needs them) but no truth.yaml, which describes the simulator's cameras and is needed
// only to render. Such a rig loads (hasTruth() false); trueCamera() and requireTruth() then refuse
// with a message naming the folder, so a scenario on `source: sim` says what is missing while the
// same scenario on real frames (images, video, recording, v4l2) runs from the calibration.

#include <string>
#include <vector>

#include "viewline/calib/synthetic.h"
#include "viewline/core/camera.h"
#include "viewline/io/config.h"

namespace viewline::scenarios {

/// A rig folder: its calibration and, for a simulated rig, the true cameras the simulator renders with.
struct SimulatedRig {
  std::string folder;                    ///< the rig folder as resolved (no trailing slash)
  calib::RigTruth truth;                 ///< what the simulator renders with (scores against); empty: no truth.yaml
  std::vector<core::Camera> calibrated;  ///< rig.yaml: what estimators use
  bool has_truth = true;                 ///< false for a calibrated-only rig (no truth.yaml)

  /// True when the folder has truth.yaml (a simulated rig); false for a calibrated-only rig.
  bool hasTruth() const { return has_truth; }
  /// Throws core::InvalidInput naming the folder, saying that truth.yaml is needed only to render,
  /// when the rig has no truth.yaml; `what` says what needed it (e.g. "source: sim renders the frames").
  void requireTruth(const std::string& what) const;
  /// Throws core::InvalidInput naming the rig folder and the known camera names (and, for a
  /// calibrated-only rig, that truth.yaml is missing: requireTruth()).
  const core::Camera& trueCamera(const std::string& name) const;
  /// The calibrated camera `name` (rig.yaml); throws core::InvalidInput as trueCamera() does.
  const core::Camera& calibratedCamera(const std::string& name) const;
  /// Path of another file of the rig folder.
  std::string file(const std::string& name) const;
};

/// Loads `<folder>/rig.yaml` and, when present, `<folder>/truth.yaml` (absent: a calibrated-only
/// rig, hasTruth() false). With both, they must list the same camera names with the same image
/// sizes; otherwise core::InvalidInput names the folder and what differs.
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
