// camera-to-ground: the camera's pose with respect to the floor (SPEC §3) from images of a board
// or an AprilTag lying flat on it, printed side up.
//   camera-to-ground --board tag.yaml --intrinsics cam.xml --camera-name cam --output ground.yaml images...
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cctype>
#include <filesystem>
#include <iomanip>
#include <iostream>

#include "tool_common.h"
#include "viewline/core/version.h"
#include "viewline/core/frames.h"
#include "viewline/io/files.h"
#include "viewline/io/rig.h"

int main(int argc, char** argv) {
  CLI::App app{"Camera-to-ground rotation (and height) from a board or tag lying on the floor."};
  app.set_version_flag("--version", std::string("viewline ") + viewline::core::kVersion);
  std::string board_file, intrinsics, camera_name = "camera", projection = "with_distortion", output;
  std::vector<std::string> images;
  int tag_id = -1;
  app.add_option("--board", board_file, "board description (YAML)")->required()->check(CLI::ExistingFile);
  app.add_option("--intrinsics", intrinsics, "ViSP camera XML or OpenCV YAML")->required()->check(CLI::ExistingFile);
  app.add_option("--camera-name", camera_name, "camera name in the XML");
  app.add_option("--projection", projection, "XML model: with_distortion | without_distortion");
  app.add_option("--tag-id", tag_id, "board type apriltag: the tag on the floor (default: the only one seen)");
  app.add_option("--output", output, "YAML to write (c_M_g, g_R_c, height, pitch, roll)");
  std::string rig_output;
  std::string ground_origin_text = "0,0";
  double ground_yaw_deg = 0.0;
  app.add_option("--rig-output", rig_output, "one-camera rig file to write (world: z up on the floor; ViSP XML only)");
  app.add_option("--ground-origin", ground_origin_text, "with --rig-output: the board's origin in the world floor, \"x,y\" (m)");
  app.add_option("--ground-yaw", ground_yaw_deg, "with --rig-output: the board's x axis, deg from world x about z");
  std::string x_hint;
  app.add_option("--board-x-hint", x_hint, "chessboard: direction of the board's x axis in the image (right|left|up|down); "
                 "the corners are renumbered from the other end when the detection runs the other way (180° symmetry)")
      ->check(CLI::IsMember({"right", "left", "up", "down"}));
  app.add_option("images", images, "image files (camera still, board still)")->required()->check(CLI::ExistingFile);
  if (const auto code = viewline::calib::tools::parseCommandLine(app, argc, argv)) return *code;
  return viewline::calib::tools::runTool("camera-to-ground", [&] {
    using namespace viewline;
    std::vector<double> ground_origin;
    {
      std::istringstream in(ground_origin_text);
      for (std::string v; std::getline(in, v, ',');) {
        try {
          ground_origin.push_back(std::stod(v));
        } catch (const std::exception&) {
          ground_origin.clear();
          break;
        }
      }
      if (ground_origin.size() != 2) throw core::InvalidInput("--ground-origin: expected \"x,y\" in metres, got '" + ground_origin_text + "'");
    }
    const calib::BoardSpec board = calib::loadBoard(board_file);
    const calib::PoseCamera cam = calib::tools::loadPoseCamera(intrinsics, camera_name, projection);
    std::vector<Eigen::Isometry3d> poses;
    for (const auto& file : images) {
      const cv::Mat gray = calib::readGray(file);
      if (board.type == calib::BoardType::AprilTag) {
        const auto tags = calib::estimateTagPoses(cam, gray, board);
        if (tag_id < 0 && tags.size() > 1)
          throw core::InvalidInput(file + ": " + std::to_string(tags.size()) + " tags seen; give --tag-id");
        auto it = tag_id < 0 ? tags.begin() : tags.find(tag_id);
        if (it == tags.end()) throw core::InvalidInput(file + ": the floor tag was not found");
        poses.push_back(it->second.c_M_o);
      } else {
        calib::Detection d = calib::detectBoard(gray, board);
        if (!d.observation) throw core::InvalidInput(file + ": " + d.reason);
        auto& pts = d.observation->image_points;
        if (!x_hint.empty() && board.type == calib::BoardType::Chessboard) {
          const cv::Point2f ax = pts[static_cast<std::size_t>(board.cols - 1)] - pts[0];
          const cv::Point2f want = x_hint == "right" ? cv::Point2f(1, 0) : x_hint == "left" ? cv::Point2f(-1, 0)
                                   : x_hint == "up" ? cv::Point2f(0, -1) : cv::Point2f(0, 1);
          if (ax.dot(want) < 0.f) std::reverse(pts.begin(), pts.end());  // the same corners, numbered from the other end
        }
        poses.push_back(calib::estimatePose(cam, d.observation->object_points, d.observation->image_points).c_M_o);
      }
    }
    const calib::GroundResult g = calib::cameraToGround(poses, board.type);
    const Eigen::Matrix3d g_R_c = g.c_M_g.linear().transpose();
    std::cout << std::fixed << std::setprecision(4) << "camera height above the ground: " << g.height_m << " m\n"
              << std::setprecision(2) << "pitch (optical axis below horizontal): " << core::rad2deg(g.pitch_rad)
              << " deg, roll: " << core::rad2deg(g.roll_rad) << " deg, spread over " << poses.size()
              << " images: " << core::rad2deg(g.spread_rad) << " deg\n"
              << std::setprecision(5) << "gravity (down) in the camera frame: [" << g.down_c().transpose() << "]\n";
    if (!output.empty()) {
      std::ostringstream y;
      y << std::setprecision(10) << "# camera-to-ground: ground frame g = z up, origin and x axis on the floor board\n"
        << "c_M_g:\n" << calib::tools::poseYaml(g.c_M_g, 2) << "g_R_c:\n";
      for (int r = 0; r < 3; ++r) y << "  - [" << g_R_c(r, 0) << ", " << g_R_c(r, 1) << ", " << g_R_c(r, 2) << "]\n";
      y << "height_m: " << g.height_m << "\npitch_deg: " << core::rad2deg(g.pitch_rad)
        << "\nroll_deg: " << core::rad2deg(g.roll_rad) << "\n";
      io::writeTextFileAtomic(output, y.str());
      std::cout << "wrote " << output << "\n";
    }
    if (!rig_output.empty()) {
      const auto lower = [](std::string e) { for (auto& ch : e) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch))); return e; };
      if (lower(std::filesystem::path(intrinsics).extension().string()) != ".xml")
        throw core::InvalidInput("--rig-output needs ViSP XML intrinsics (--intrinsics " + intrinsics + ")");
      core::Camera rig_cam;
      rig_cam.name = camera_name;
      const auto xml = io::loadVispCameraXml(intrinsics, camera_name,
                                             projection == "without_distortion" ? io::Projection::WithoutDistortion
                                                                                 : io::Projection::WithDistortion);
      rig_cam.intrinsics = xml.intrinsics;
      rig_cam.width = xml.width;
      rig_cam.height = xml.height;
      Eigen::Isometry3d w_M_g = Eigen::Isometry3d::Identity();
      w_M_g.linear() = core::rotation(Eigen::Vector3d::UnitZ(), core::deg2rad(ground_yaw_deg));
      w_M_g.translation() = Eigen::Vector3d(ground_origin[0], ground_origin[1], 0.0);
      rig_cam.c_M_w = g.c_M_g * w_M_g.inverse();
      std::ostringstream comment;
      comment << "camera-to-ground from " << poses.size() << " images: world z up on the floor, board origin at ("
              << ground_origin[0] << ", " << ground_origin[1] << ") m, yaw " << ground_yaw_deg << " deg";
      for (const auto& f : io::saveRig(rig_output, {rig_cam}, comment.str())) std::cout << "wrote " << f << "\n";
    }
    return 0;
  });
}
