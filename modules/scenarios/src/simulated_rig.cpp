#include "viewline/scenarios/simulated_rig.h"

#include <sstream>

#include "viewline/core/error.h"
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

const core::Camera& SimulatedRig::trueCamera(const std::string& name) const {
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
  rig.truth = calib::loadRigTruth(rig.file("truth.yaml"));
  rig.calibrated = io::loadRig(rig.file("rig.yaml"));
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

}  // namespace viewline::scenarios
