// camera-to-ground: the camera's pose with respect to the floor (SPEC §3) from images of a board
// or an AprilTag lying flat on it, printed side up.
//   camera-to-ground --board tag.yaml --intrinsics cam.xml --camera-name cam --output ground.yaml images...
#include <CLI/CLI.hpp>
#include <iomanip>
#include <iostream>

#include "tool_common.h"
#include "viewline/core/frames.h"
#include "viewline/io/files.h"

int main(int argc, char** argv) {
  CLI::App app{"Camera-to-ground rotation (and height) from a board or tag lying on the floor."};
  std::string board_file, intrinsics, camera_name = "camera", projection = "with_distortion", output;
  std::vector<std::string> images;
  int tag_id = -1;
  app.add_option("--board", board_file, "board description (YAML)")->required();
  app.add_option("--intrinsics", intrinsics, "ViSP camera XML or OpenCV YAML")->required();
  app.add_option("--camera-name", camera_name, "camera name in the XML");
  app.add_option("--projection", projection, "XML model: with_distortion | without_distortion");
  app.add_option("--tag-id", tag_id, "board type apriltag: the tag on the floor (default: the only one seen)");
  app.add_option("--output", output, "YAML to write (c_M_g, g_R_c, height, pitch, roll)");
  app.add_option("images", images, "image files (camera still, board still)")->required();
  CLI11_PARSE(app, argc, argv);
  return viewline::calib::tools::runTool("camera-to-ground", [&] {
    using namespace viewline;
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
        const calib::Detection d = calib::detectBoard(gray, board);
        if (!d.observation) throw core::InvalidInput(file + ": " + d.reason);
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
    return 0;
  });
}
