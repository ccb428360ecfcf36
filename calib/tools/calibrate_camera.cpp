// calibrate-camera: intrinsic calibration from images of a board.
//   calibrate-camera --board board.yaml --name left --output-xml left.xml --output-yaml left.yaml images...
#include <CLI/CLI.hpp>
#include <iostream>

#include "tool_common.h"
#include "viewline/core/version.h"
#include "viewline/calib/intrinsics.h"
#include "viewline/io/files.h"

int main(int argc, char** argv) {
  CLI::App app{"Intrinsic calibration from images of a chessboard, circle grid, AprilTag grid or ChArUco board.\n"
               "Writes a ViSP camera XML (models with and without distortion) and an OpenCV YAML."};
  app.set_version_flag("--version", std::string("viewline ") + viewline::core::kVersion);
  std::string board_file, name = "camera", xml, yaml, report;
  std::vector<std::string> images;
  int min_views = 3;
  double max_view_rms = 3.0;
  app.add_option("--board", board_file, "board description (YAML)")->required()->check(CLI::ExistingFile);
  app.add_option("--name", name, "camera name in the XML file");
  app.add_option("--output-xml", xml, "ViSP camera XML to write");
  app.add_option("--output-yaml", yaml, "OpenCV YAML to write");
  app.add_option("--report", report, "JSON report to write (parameters, std devs, per-view errors)");
  app.add_option("--min-views", min_views, "fewest usable views accepted");
  app.add_option("--max-view-rms", max_view_rms, "views with a larger RMS error (px) are rejected");
  app.add_option("images", images, "image files")->required()->check(CLI::ExistingFile);
  if (const auto code = viewline::calib::tools::parseCommandLine(app, argc, argv)) return *code;
  return viewline::calib::tools::runTool("calibrate-camera", [&] {
    using namespace viewline;
    if (xml.empty() && yaml.empty()) throw core::InvalidInput("give --output-xml and/or --output-yaml");
    const calib::BoardSpec board = calib::loadBoard(board_file);
    calib::IntrinsicsOptions opt;
    opt.min_views = min_views;
    opt.max_view_rms_px = max_view_rms;
    std::cout << "board: " << board.describe() << ", " << images.size() << " images\n";
    const calib::IntrinsicsResult r = calib::calibrateFromImages(images, board, opt);
    std::cout << r.report();
    calib::saveIntrinsics(r, name, xml, yaml);
    if (!report.empty()) {
      nlohmann::json j;
      j["camera"] = name;
      j["image_size"] = {r.image_size.width, r.image_size.height};
      j["rms_px"] = r.rms_px;
      j["camera_matrix"] = {r.opencv.camera_matrix(0, 0), r.opencv.camera_matrix(1, 1), r.opencv.camera_matrix(0, 2),
                            r.opencv.camera_matrix(1, 2)};
      j["distortion"] = std::vector<double>(r.opencv.distortion.data(), r.opencv.distortion.data() + r.opencv.distortion.size());
      j["std_dev"] = std::vector<double>(r.std_dev.data(), r.std_dev.data() + r.std_dev.size());
      j["visp_with_distortion"] = {{"px", r.visp_with.get_px()}, {"py", r.visp_with.get_py()}, {"u0", r.visp_with.get_u0()},
                                   {"v0", r.visp_with.get_v0()}, {"kud", r.visp_with.get_kud()}, {"kdu", r.visp_with.get_kdu()},
                                   {"rms_px", r.visp_with_rms_px}};
      j["visp_without_distortion_rms_px"] = r.visp_without_rms_px;
      for (std::size_t i = 0; i < r.view_names.size(); ++i) j["views"].push_back({{"image", r.view_names[i]}, {"rms_px", r.view_rms_px[i]}});
      for (const auto& rej : r.rejected) j["rejected"].push_back({{"image", rej.name}, {"reason", rej.reason}});
      io::writeJsonFile(report, j);
    }
    if (!xml.empty()) std::cout << "wrote " << xml << "\n";
    if (!yaml.empty()) std::cout << "wrote " << yaml << "\n";
    return 0;
  });
}
