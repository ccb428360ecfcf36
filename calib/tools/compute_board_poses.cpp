// compute-board-poses: the pose c_M_o of a board (or of every AprilTag) in each image.
//   compute-board-poses --board board.yaml --intrinsics cam.xml --camera-name cam --output poses.yaml images...
#include <CLI/CLI.hpp>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "tool_common.h"
#include "viewline/core/version.h"
#include "viewline/core/frames.h"
#include "viewline/io/files.h"

int main(int argc, char** argv) {
  CLI::App app{"Pose of a calibration board (or of each AprilTag) in each image, from calibrated intrinsics."};
  app.set_version_flag("--version", std::string("viewline ") + viewline::core::kVersion);
  std::string board_file, intrinsics, camera_name = "camera", projection = "with_distortion", output;
  std::vector<std::string> images;
  app.add_option("--board", board_file, "board description (YAML)")->required()->check(CLI::ExistingFile);
  app.add_option("--intrinsics", intrinsics, "ViSP camera XML or OpenCV YAML")->required()->check(CLI::ExistingFile);
  app.add_option("--camera-name", camera_name, "camera name in the XML");
  app.add_option("--projection", projection, "XML model: with_distortion | without_distortion");
  app.add_option("--output", output, "poses file (YAML) to write");
  app.add_option("images", images, "image files")->required()->check(CLI::ExistingFile);
  if (const auto code = viewline::calib::tools::parseCommandLine(app, argc, argv)) return *code;
  return viewline::calib::tools::runTool("compute-board-poses", [&] {
    using namespace viewline;
    using calib::tools::poseYaml;
    const calib::BoardSpec board = calib::loadBoard(board_file);
    const calib::PoseCamera cam = calib::tools::loadPoseCamera(intrinsics, camera_name, projection);
    std::ostringstream y;
    y << std::setprecision(8) << "# compute-board-poses: c_M_o maps board (or tag) coordinates to camera coordinates\n"
      << "board: " << board.describe() << "\nposes:\n";
    std::size_t found = 0;
    for (const auto& file : images) {
      const cv::Mat gray = calib::readGray(file);
      y << "  - image: " << file << "\n";
      if (board.type == calib::BoardType::AprilTag) {
        const auto tags = calib::estimateTagPoses(cam, gray, board);
        y << "    found: " << (tags.empty() ? "false" : "true") << "\n";
        std::cout << file << ": " << tags.size() << " tags\n";
        if (!tags.empty()) {
          ++found;
          y << "    tags:\n";
        }
        for (const auto& [id, p] : tags) {
          const Eigen::AngleAxisd aa(p.c_M_o.linear());
          std::cout << "  tag " << id << ": t = [" << p.c_M_o.translation().transpose() << "] m, theta-u = ["
                    << (aa.angle() * aa.axis()).transpose() << "] rad, RMS " << p.rms_px << " px\n";
          y << "      - id: " << id << "\n        rms_px: " << p.rms_px << "\n        c_M_o:\n" << poseYaml(p.c_M_o, 10);
        }
        continue;
      }
      const calib::Detection d = calib::detectBoard(gray, board);
      if (!d.observation) {
        std::cout << file << ": not found (" << d.reason << ")\n";
        y << "    found: false\n    reason: \"" << d.reason << "\"\n";
        continue;
      }
      const calib::BoardPose p = calib::estimatePose(cam, d.observation->object_points, d.observation->image_points);
      ++found;
      std::cout << file << ": t = [" << p.c_M_o.translation().transpose() << "] m, RMS " << p.rms_px << " px\n";
      y << "    found: true\n    rms_px: " << p.rms_px << "\n    c_M_o:\n" << poseYaml(p.c_M_o, 6);
    }
    if (found == 0) throw core::InvalidInput("the board was found in none of the " + std::to_string(images.size()) + " images");
    if (!output.empty()) {
      io::writeTextFileAtomic(output, y.str());
      std::cout << "wrote " << output << " (" << found << " of " << images.size() << " images with a pose)\n";
    }
    return 0;
  });
}
