// tutorial-picture: the small pictures of the tutorial pages (scripts/make-tutorial-pictures).
//   tutorial-picture --input IMAGE [--input IMAGE2 ...] [--board BOARD.yaml] [--width W] --output PICTURE.png
// Reads the images, draws on each what calib::detectBoard finds (the detector the calibration tools
// use) when a board is given, shrinks them side by side to W pixels in all and writes a small PNG
// (grey levels reduced to 64, so that the sensor noise of rendered views does not make it large).
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <iostream>
#include <optional>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "viewline/core/version.h"
#include "viewline/calib/board.h"
#include "viewline/core/error.h"

namespace {

cv::Mat picture(const std::string& input, const viewline::calib::BoardSpec* board, int width) {
  using namespace viewline;
  const cv::Mat gray = calib::readGray(input);
  cv::Mat small;
  const double k = static_cast<double>(width) / gray.cols;
  cv::resize(gray, small, cv::Size(width, static_cast<int>(std::lround(gray.rows * k))), 0, 0,
             k < 1 ? cv::INTER_AREA : cv::INTER_LINEAR);
  small.forEach<unsigned char>([](unsigned char& v, const int*) { v = static_cast<unsigned char>(v & 0xfc); });
  cv::Mat out;
  cv::cvtColor(small, out, cv::COLOR_GRAY2BGR);
  if (!board) return out;
  const calib::Detection d = calib::detectBoard(gray, *board);
  if (!d.observation) throw core::InvalidInput(input + ": " + d.reason);
  const auto& pts = d.observation->image_points;
  const int r = std::max(2, width / 160);
  for (std::size_t i = 0; i < pts.size(); ++i) {
    // first point red, last blue: the order in which the tools number the points
    const double f = pts.size() > 1 ? static_cast<double>(i) / static_cast<double>(pts.size() - 1) : 0.0;
    cv::circle(out, cv::Point2d(static_cast<double>(pts[i].x) * k, static_cast<double>(pts[i].y) * k), r,
               cv::Scalar(255 * f, 96, 255 * (1 - f)), 1, cv::LINE_AA);
  }
  std::cout << input << ": " << pts.size() << " points detected\n";
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Writes a small PNG of images side by side, with the detected board drawn on them."};
  app.set_version_flag("--version", std::string("viewline ") + viewline::core::kVersion);
  std::vector<std::string> inputs;
  std::string board_file, output;
  int width = 320;
  app.add_option("--input", inputs, "image (any format OpenCV reads); repeat for side by side")->required()->check(CLI::ExistingFile);
  app.add_option("--board", board_file, "board description: draw its detection")->check(CLI::ExistingFile);
  app.add_option("--width", width, "width of the picture, px")->check(CLI::Range(32, 2000));
  app.add_option("--output", output, "PNG to write")->required();
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;  // usage error: 2, as in every viewline tool (CLI11_PARSE: CLI11's codes)
  }
  try {
    using namespace viewline;
    std::optional<calib::BoardSpec> board;
    if (!board_file.empty()) board = calib::loadBoard(board_file);
    std::vector<cv::Mat> parts;
    const int each = (width - 4 * static_cast<int>(inputs.size() - 1)) / static_cast<int>(inputs.size());
    int height = 0;
    for (const auto& in : inputs) {
      parts.push_back(picture(in, board ? &*board : nullptr, each));
      height = std::max(height, parts.back().rows);
    }
    cv::Mat out(height, width, CV_8UC3, cv::Scalar(255, 255, 255));
    int x = 0;
    for (const auto& p : parts) {
      p.copyTo(out(cv::Rect(x, 0, p.cols, p.rows)));
      x += p.cols + 4;
    }
    if (inputs.size() == 1) out = out(cv::Rect(0, 0, parts[0].cols, parts[0].rows)).clone();
    if (!board) cv::cvtColor(out, out, cv::COLOR_BGR2GRAY);
    if (!cv::imwrite(output, out, {cv::IMWRITE_PNG_COMPRESSION, 9})) throw core::InvalidInput(output + ": cannot write");
    std::cout << "wrote " << output << " (" << out.cols << "x" << out.rows << ")\n";
  } catch (const std::exception& e) {
    std::cerr << "tutorial-picture: error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
