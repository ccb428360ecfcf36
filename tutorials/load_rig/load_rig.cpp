// Loads a rig file written by calibrate-rig (or by hand) and prints each camera: this is all an
// app does to get its calibrated cameras (io::loadRig -> std::vector<core::Camera>).
// With a second argument, a simulated rig's truth file (calib/rigs/<rig>/truth.yaml): also loads
// the true cameras the simulator renders with (calib::loadRigTruth) and prints how far off the
// calibration is -- a simulated app renders with the truth and estimates with the calibration.
#include <iostream>
#include <string>

#include "viewline/core/version.h"
#include "viewline/calib/synthetic.h"
#include "viewline/core/frames.h"

#include "viewline/core/error.h"
#include "viewline/io/rig.h"

namespace {
const char* const kUsage =
    "usage: load_rig RIG.yaml [TRUTH.yaml]\n"
    "  prints each camera of the rig file (calibrate-rig's output or calib/rigs/<rig>/rig.yaml);\n"
    "  with a simulated rig's truth file, also how far the calibration is from the truth\n";
}  // namespace

int main(int argc, char** argv) {
  if (argc == 2 && (std::string(argv[1]) == "--help" || std::string(argv[1]) == "-h")) {
    std::cout << kUsage;
    return 0;
  }
  if (argc == 2 && std::string(argv[1]) == "--version") {
    std::cout << "viewline " << viewline::core::kVersion << "\n";
    return 0;
  }
  if ((argc != 2 && argc != 3) || argv[1][0] == '-') {
    if (argc >= 2 && argv[1][0] == '-') std::cerr << "load_rig: unknown option " << argv[1] << "\n";
    std::cerr << kUsage;
    return 2;
  }
  try {
    const std::vector<viewline::core::Camera> cameras = viewline::io::loadRig(argv[1]);
    for (const auto& c : cameras) {
      std::cout << c.name << ": " << c.width << "x" << c.height << ", px " << c.intrinsics.get_px() << ", py "
                << c.intrinsics.get_py() << ", kud " << c.intrinsics.get_kud() << ", centre in world ["
                << c.center_w().transpose() << "] m\n";
      // Project a world point 1 m in front of the first camera.
      const auto uv = c.project(cameras.front().c_M_w.inverse() * Eigen::Vector3d(0, 0, 1));
      if (uv) std::cout << "  sees (0, 0, 1) of " << cameras.front().name << " at pixel [" << uv->transpose() << "]\n";
    }
    if (argc == 3) {
      const viewline::calib::RigTruth truth = viewline::calib::loadRigTruth(argv[2]);
      for (const auto& e : viewline::calib::compareRig(truth.cameras, cameras))
        std::cout << "truth of " << e.name << ": px " << e.truth.get_px() << ", kud " << e.truth.get_kud()
                  << "; calibration off by " << 1e3 * e.position_error_m << " mm, "
                  << viewline::core::rad2deg(e.rotation_error_rad) << " deg, rays " << e.world_ray_rms_px << " px RMS\n";
    }
  } catch (const std::exception& e) {
    std::cerr << "load_rig: error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
