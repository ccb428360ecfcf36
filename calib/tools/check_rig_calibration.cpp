// check-rig-calibration: a calibrated rig against the truth it was rendered from (simulated rigs).
//   check-rig-calibration --truth calib/rigs/dart/truth.yaml --rig calib/rigs/dart/rig.yaml [--e-M-c e_M_c.yaml]
// Prints one Markdown table row per camera: focal lengths, principal point, distortion (true /
// calibrated), camera centre and rotation errors, the ray errors of calib::compareCamera, and the
// floor of that ray error: the truth's own ViSP back-projection (fitted kdu) against its exact
// inverse (ViSP's one-coefficient kdu model cannot invert the kud model exactly).
// With --max-ray-px / --max-position / --max-rotation, exits 3 when a camera exceeds them.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <iostream>

#include "tool_common.h"
#include "viewline/core/version.h"
#include "viewline/calib/synthetic.h"
#include "viewline/core/frames.h"
#include "viewline/io/config.h"
#include "viewline/io/rig.h"

int main(int argc, char** argv) {
  CLI::App app{"Compares a calibrated rig with the true rig of a truth file."};
  app.set_version_flag("--version", std::string("viewline ") + viewline::core::kVersion);
  std::string truth_file, rig_file, emc_file;
  double max_ray = -1, max_pos = -1, max_rot_deg = -1;
  app.add_option("--truth", truth_file, "truth file")->required()->check(CLI::ExistingFile);
  app.add_option("--rig", rig_file, "calibrated rig file (io::loadRig)")->required()->check(CLI::ExistingFile);
  app.add_option("--e-M-c", emc_file, "calibrate-hand-eye output to compare with the truth's hand_eye.e_M_c")->check(CLI::ExistingFile);
  app.add_option("--max-ray-px", max_ray, "fail (exit 3) when a camera's RMS world-ray error exceeds this (px)");
  app.add_option("--max-position", max_pos, "fail when a camera centre is off by more than this (m)");
  app.add_option("--max-rotation", max_rot_deg, "fail when a camera rotation is off by more than this (deg)");
  if (const auto code = viewline::calib::tools::parseCommandLine(app, argc, argv)) return *code;
  return viewline::calib::tools::runTool("check-rig-calibration", [&] {
    using namespace viewline;
    const calib::RigTruth truth = calib::loadRigTruth(truth_file);
    const auto cal = io::loadRig(rig_file);
    const auto errs = calib::compareRig(truth.cameras, cal);
    bool ok = true;
    std::printf("| rig | camera | fx true/cal | fy true/cal | cx true/cal | cy true/cal | kud true/cal | kdu true/cal "
                "| centre err mm | rot err deg | ray RMS/max px | world-ray RMS/max px | ViSP-model floor px |\n"
                "|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
    for (const auto& e : errs) {
      const auto& t = e.truth;
      const auto& c = e.calibrated;
      std::printf("| %s | %s | %.2f / %.2f | %.2f / %.2f | %.2f / %.2f | %.2f / %.2f | %.4f / %.4f | %.4f / %.4f | %.1f | %.3f "
                  "| %.2f / %.2f | %.2f / %.2f | %.2f |\n",
                  truth.name.c_str(), e.name.c_str(), t.get_px(), c.get_px(), t.get_py(), c.get_py(), t.get_u0(), c.get_u0(),
                  t.get_v0(), c.get_v0(), t.get_kud(), c.get_kud(), t.get_kdu(), c.get_kdu(), 1e3 * e.position_error_m,
                  core::rad2deg(e.rotation_error_rad), e.ray_rms_px, e.ray_max_px, e.world_ray_rms_px, e.world_ray_max_px,
                  calib::compareCamera(truth.camera(e.name), truth.camera(e.name)).ray_rms_px);
      if (max_ray >= 0 && e.world_ray_rms_px > max_ray) ok = false;
      if (max_pos >= 0 && e.position_error_m > max_pos) ok = false;
      if (max_rot_deg >= 0 && core::rad2deg(e.rotation_error_rad) > max_rot_deg) ok = false;
    }
    if (!emc_file.empty()) {
      if (!truth.e_M_c) throw core::InvalidInput(truth_file + ": no hand_eye section to compare --e-M-c with");
      const auto y = io::ConfigNode::loadFile(emc_file);
      const Eigen::Isometry3d X = io::readPose(y.child("e_M_c"));
      const double dt = (X.translation() - truth.e_M_c->translation()).norm();
      const double dr = core::rotationAngle(X.linear(), truth.e_M_c->linear());
      std::printf("\ne_M_c: translation true [%.4f %.4f %.4f] calibrated [%.4f %.4f %.4f] m, error %.1f mm; rotation error %.3f deg\n",
                  truth.e_M_c->translation().x(), truth.e_M_c->translation().y(), truth.e_M_c->translation().z(),
                  X.translation().x(), X.translation().y(), X.translation().z(), 1e3 * dt, core::rad2deg(dr));
      if (max_pos >= 0 && dt > max_pos) ok = false;
      if (max_rot_deg >= 0 && core::rad2deg(dr) > max_rot_deg) ok = false;
    }
    if (!ok) {
      std::cout << "FAILED: a calibrated value is outside the given bounds\n";
      return 3;
    }
    return 0;
  });
}
