// calibrate-hand-eye: vpHandEyeCalibration from robot poses and board poses.
//   calibrate-hand-eye --setup eye-in-hand --robot-poses robot.yaml --camera-poses poses.yaml --output e_M_c.yaml
// robot.yaml:  poses: [ {r_M_e: {translation: [..], rotation: [[..]..] | theta_u_deg: [..]}, q_deg: [..]}, ... ]
//              (q_deg, the joint angles, is optional and informative only)
// --rig-output rig.yaml --intrinsics cam.xml: also writes a one-camera rig (io::saveRig) whose world
// is the robot base frame, with the camera where it is at robot pose --rig-pose (eye-in-hand:
// c_M_r = (r_M_e(k) e_M_c)^-1; eye-to-hand: c_M_r = r_M_c^-1, whatever --rig-pose).
// poses.yaml:  the output of compute-board-poses (same order; pairs whose board was not found are dropped).
#include <CLI/CLI.hpp>
#include <iostream>

#include "tool_common.h"
#include "viewline/core/version.h"
#include "viewline/calib/hand_eye.h"
#include "viewline/core/frames.h"
#include "viewline/io/files.h"
#include "viewline/io/rig.h"

int main(int argc, char** argv) {
  CLI::App app{"Hand-eye calibration (eye-in-hand or eye-to-hand) with vpHandEyeCalibration."};
  app.set_version_flag("--version", std::string("viewline ") + viewline::core::kVersion);
  std::string setup = "eye-in-hand", robot_file, camera_file, output;
  app.add_option("--setup", setup, "eye-in-hand (camera on the end effector) | eye-to-hand (camera fixed)")
      ->check(CLI::IsMember({"eye-in-hand", "eye-to-hand"}));
  app.add_option("--robot-poses", robot_file, "YAML list of r_M_e (end effector in robot base)")->required()->check(CLI::ExistingFile);
  app.add_option("--camera-poses", camera_file, "compute-board-poses output (c_M_o per image)")->required()->check(CLI::ExistingFile);
  app.add_option("--output", output, "YAML to write (e_M_c or r_M_c, residuals)");
  std::string rig_output, intrinsics, camera_name = "camera";
  std::size_t rig_pose = 0;
  auto* rig_output_opt = app.add_option("--rig-output", rig_output, "one-camera rig file to write (world = robot base frame)");
  auto* intrinsics_opt =
      app.add_option("--intrinsics", intrinsics, "with --rig-output: ViSP camera XML (calibrate-camera's)")->check(CLI::ExistingFile);
  rig_output_opt->needs(intrinsics_opt);  // a usage error (exit 2) before any file is read
  app.add_option("--camera-name", camera_name, "with --rig-output: camera name in the XML and in the rig");
  app.add_option("--rig-pose", rig_pose, "with --rig-output, eye-in-hand: index of the robot pose the rig is written at");
  if (const auto code = viewline::calib::tools::parseCommandLine(app, argc, argv)) return *code;
  return viewline::calib::tools::runTool("calibrate-hand-eye", [&] {
    using namespace viewline;
    const auto robot = io::ConfigNode::loadFile(robot_file);
    std::vector<Eigen::Isometry3d> r_M_e;
    for (const auto& p : robot.childList("poses")) {
      r_M_e.push_back(io::readPose(p.child("r_M_e")));
      p.ignore("q_deg");
    }
    if (!rig_output.empty() && intrinsics.empty()) throw core::InvalidInput("--rig-output needs --intrinsics");
    if (!rig_output.empty() && rig_pose >= r_M_e.size())
      throw core::InvalidInput("--rig-pose " + std::to_string(rig_pose) + ": " + robot_file + " has " + std::to_string(r_M_e.size()) + " poses");
    robot.finish();
    const auto cams = io::ConfigNode::loadFile(camera_file);
    cams.ignore("board");
    const auto entries = cams.childList("poses");
    if (entries.size() != r_M_e.size())
      throw core::InvalidInput(camera_file + ": " + std::to_string(entries.size()) + " images but " + robot_file + " has " +
                               std::to_string(r_M_e.size()) + " robot poses (they pair up in order)");
    std::vector<Eigen::Isometry3d> rm, cm;
    for (std::size_t i = 0; i < entries.size(); ++i) {
      const auto& e = entries[i];
      const std::string image = e.get<std::string>("image");
      if (!e.get<bool>("found")) {
        e.ignore("reason");
        std::cout << "dropping pose " << i << ": no board in " << image << "\n";
        continue;
      }
      e.ignore("rms_px");
      rm.push_back(r_M_e[i]);
      cm.push_back(io::readPose(e.child("c_M_o")));
    }
    cams.finish();
    const auto s = setup == "eye-in-hand" ? calib::HandEyeSetup::EyeInHand : calib::HandEyeSetup::EyeToHand;
    const calib::HandEyeResult r = calib::calibrateHandEye(rm, cm, s);
    std::cout << r.report();
    if (!output.empty()) {
      const bool in = s == calib::HandEyeSetup::EyeInHand;
      std::ostringstream y;
      y << "# calibrate-hand-eye (" << setup << ", " << rm.size() << " poses)\n"
        << (in ? "e_M_c:\n" : "r_M_c:\n") << calib::tools::poseYaml(r.X, 2) << (in ? "r_M_o:\n" : "e_M_o:\n")
        << calib::tools::poseYaml(r.fixed, 2) << "rms_translation_m: " << r.rms_translation_m
        << "\nrms_rotation_deg: " << core::rad2deg(r.rms_rotation_rad) << "\n";
      io::writeTextFileAtomic(output, y.str());
      std::cout << "wrote " << output << "\n";
    }
    if (!rig_output.empty()) {
      core::Camera cam;
      cam.name = camera_name;
      const auto xml = io::loadVispCameraXml(intrinsics, camera_name, io::Projection::WithDistortion);
      cam.intrinsics = xml.intrinsics;
      cam.width = xml.width;
      cam.height = xml.height;
      const bool in = s == calib::HandEyeSetup::EyeInHand;
      cam.c_M_w = in ? (r_M_e[rig_pose] * r.X).inverse() : r.X.inverse();
      std::ostringstream comment;
      comment << "calibrate-hand-eye (" << setup << ", " << rm.size() << " poses): world = robot base frame"
              << (in ? ", camera at robot pose " + std::to_string(rig_pose) : std::string());
      for (const auto& f : io::saveRig(rig_output, {cam}, comment.str())) std::cout << "wrote " << f << "\n";
    }
    return 0;
  });
}
