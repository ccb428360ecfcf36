#include "viewline/scenarios/simulated_rig.h"

#include <filesystem>
#include <sstream>

#include "viewline/core/error.h"
#include "viewline/core/frames.h"
#include "viewline/io/rig.h"

namespace viewline::scenarios {

namespace {
const core::Camera& findCamera(const std::vector<core::Camera>& cameras, const std::string& name,
                               const std::string& where) {
  std::ostringstream known;
  for (const auto& c : cameras) {
    if (c.name == name) return c;
    known << (known.tellp() > 0 ? ", " : "") << c.name;
  }
  throw core::InvalidInput(where + ": no camera named '" + name + "' (cameras: " + known.str() + ")");
}
}  // namespace

void SimulatedRig::requireTruth(const std::string& what) const {
  if (has_truth) return;
  throw core::InvalidInput(folder + " has no truth.yaml (a calibrated-only rig): " + what +
                           ", and truth.yaml (the simulator's cameras) is needed only to render; run this rig on real "
                           "frames (source: images, video, recording or v4l2) or add truth.yaml");
}

const core::Camera& SimulatedRig::trueCamera(const std::string& name) const {
  requireTruth("its true camera '" + name + "' was asked for");
  return findCamera(truth.cameras, name, folder + "/truth.yaml");
}

const core::Camera& SimulatedRig::calibratedCamera(const std::string& name) const {
  return findCamera(calibrated, name, folder + "/rig.yaml");
}

std::string SimulatedRig::file(const std::string& name) const { return folder + "/" + name; }

SimulatedRig loadSimulatedRig(const std::string& folder_in) {
  SimulatedRig rig;
  rig.folder = folder_in;
  while (rig.folder.size() > 1 && rig.folder.back() == '/') rig.folder.pop_back();
  rig.calibrated = io::loadRig(rig.file("rig.yaml"));
  // Only the simulator needs truth.yaml: without it the rig is calibrated only (a real rig).
  rig.has_truth = std::filesystem::exists(rig.file("truth.yaml"));
  if (!rig.has_truth) return rig;
  rig.truth = calib::loadRigTruth(rig.file("truth.yaml"));
  if (rig.truth.cameras.size() != rig.calibrated.size()) {
    throw core::InvalidInput(rig.folder + ": truth.yaml has " + std::to_string(rig.truth.cameras.size()) +
                             " cameras but rig.yaml has " + std::to_string(rig.calibrated.size()) +
                             " (re-run scripts/calibrate-default-rigs)");
  }
  for (const auto& t : rig.truth.cameras) {
    const core::Camera& c = rig.calibratedCamera(t.name);
    if (c.width != t.width || c.height != t.height) {
      throw core::InvalidInput(rig.folder + ": camera '" + t.name + "' is " + std::to_string(t.width) + "x" +
                               std::to_string(t.height) + " in truth.yaml but " + std::to_string(c.width) + "x" +
                               std::to_string(c.height) + " in rig.yaml");
    }
  }
  return rig;
}

SimulatedRig loadSimulatedRig(const io::ConfigNode& cfg, const std::string& key) {
  const std::string folder = cfg.getPath(key);
  try {
    return loadSimulatedRig(folder);
  } catch (const core::InvalidInput& e) {
    throw core::InvalidInput(cfg.location(key) + ": key '" + cfg.keyPath(key) + "': " + e.what());
  }
}

Eigen::Matrix3d loadGroundRotation(const SimulatedRig& rig, const std::string& camera_name) {
  const core::Camera& cam = rig.calibratedCamera(camera_name);
  const std::string file = rig.file("ground.yaml");
  const io::ConfigNode g = io::ConfigNode::loadFile(file);
  const Eigen::Matrix3d g_R_c = g.get<Eigen::Matrix3d>("g_R_c");
  g.ignore("c_M_g");  // the full pose is rig.yaml's c_M_w (the board placed at its surveyed spot)
  g.ignore("height_m");
  g.ignore("pitch_deg");
  g.ignore("roll_deg");
  g.finish();
  if ((g_R_c.transpose() * g_R_c - Eigen::Matrix3d::Identity()).norm() > 1e-6 || g_R_c.determinant() < 0.0) {
    throw core::InvalidInput(file + ": g_R_c is not a rotation");
  }
  const double off = core::rotationAngle(g_R_c.transpose(), cam.c_M_w.linear());
  if (off > core::deg2rad(0.01)) {
    throw core::InvalidInput(file + ": g_R_c differs from the rotation of camera '" + camera_name + "' in rig.yaml by " +
                             std::to_string(core::rad2deg(off)) + " deg (re-run scripts/calibrate-default-rigs)");
  }
  return g_R_c;
}

}  // namespace viewline::scenarios
