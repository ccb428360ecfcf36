// tutorial-picture: the small pictures of the tutorial pages (scripts/make-tutorial-pictures).
//   tutorial-picture --input IMAGE [--input IMAGE2 ...] [--board BOARD.yaml] [--path TRACK.csv
//                    [--columns U,V]] [--width W] --output PICTURE.png
// Reads the images, draws on each what calib::detectBoard finds (the detector the calibration tools
// use) when a board is given, shrinks them side by side to W pixels in all and writes a small PNG
// (grey levels reduced to 64, so that the sensor noise of rendered views does not make it large).
// --path draws a tracked image path on a single image: the `u`, `v` columns (or those --columns
// names; pixels of the input image) of a CSV with a header row, rows with `detected` 0 left out,
// the last point circled.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <iostream>
#include <optional>
#include <sstream>
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

std::vector<std::string> splitCsv(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream ss(line);
  std::string cell;
  while (std::getline(ss, cell, ',')) out.push_back(cell);
  return out;
}

// The detected (u, v) points of a track CSV, in file order.
std::vector<cv::Point2d> readPath(const std::string& path, const std::string& col_u, const std::string& col_v) {
  using viewline::core::InvalidInput;
  std::ifstream in(path);
  if (!in) throw InvalidInput(path + ": cannot read");
  std::string line;
  if (!std::getline(in, line)) throw InvalidInput(path + ": empty (expected a header row)");
  const std::vector<std::string> head = splitCsv(line);
  const auto column = [&](const std::string& name) {
    return static_cast<std::ptrdiff_t>(std::find(head.begin(), head.end(), name) - head.begin());
  };
  const std::ptrdiff_t cu = column(col_u), cv_ = column(col_v), cd = column("detected");
  const auto n = static_cast<std::ptrdiff_t>(head.size());
  if (cu == n || cv_ == n) throw InvalidInput(path + ": needs columns named " + col_u + " and " + col_v);
  std::vector<cv::Point2d> pts;
  for (int row = 2; std::getline(in, line); ++row) {
    if (line.empty()) continue;
    const std::vector<std::string> f = splitCsv(line);
    if (static_cast<std::ptrdiff_t>(f.size()) != n)
      throw InvalidInput(path + ":" + std::to_string(row) + ": " + std::to_string(f.size()) + " fields, header has " +
                         std::to_string(n));
    if (cd != n && f[static_cast<std::size_t>(cd)] == "0") continue;
    try {
      pts.emplace_back(std::stod(f[static_cast<std::size_t>(cu)]), std::stod(f[static_cast<std::size_t>(cv_)]));
    } catch (const std::exception&) {
      throw InvalidInput(path + ":" + std::to_string(row) + ": " + col_u + ", " + col_v + " are not numbers");
    }
  }
  if (pts.empty()) throw InvalidInput(path + ": no detected point");
  return pts;
}

void drawPath(cv::Mat& out, const std::vector<cv::Point2d>& pts, double k) {
  std::vector<cv::Point> line;
  for (const auto& p : pts) line.emplace_back(static_cast<int>(std::lround(p.x * k)), static_cast<int>(std::lround(p.y * k)));
  cv::polylines(out, line, false, cv::Scalar(0, 160, 255), 1, cv::LINE_AA);
  cv::circle(out, line.back(), std::max(6, out.cols / 20), cv::Scalar(0, 0, 255), 1, cv::LINE_AA);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Writes a small PNG of images side by side, with the detected board drawn on them."};
  app.set_version_flag("--version", std::string("viewline ") + viewline::core::kVersion);
  std::vector<std::string> inputs;
  std::string board_file, path_file, columns = "u,v", output;
  int width = 320;
  app.add_option("--input", inputs, "image (any format OpenCV reads); repeat for side by side")->required()->check(CLI::ExistingFile);
  app.add_option("--board", board_file, "board description: draw its detection")->check(CLI::ExistingFile);
  app.add_option("--path", path_file, "CSV with u, v columns (and optional detected): draw the path on the image")
      ->check(CLI::ExistingFile);
  app.add_option("--columns", columns, "the path's two pixel columns, U,V")->capture_default_str();
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
    if (!path_file.empty() && inputs.size() != 1) throw core::InvalidInput("--path draws on a single --input");
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
    if (!path_file.empty()) {
      const std::size_t comma = columns.find(',');
      if (comma == std::string::npos || comma == 0 || comma + 1 == columns.size())
        throw core::InvalidInput("--columns: expected two names, U,V (got '" + columns + "')");
      const std::vector<cv::Point2d> pts = readPath(path_file, columns.substr(0, comma), columns.substr(comma + 1));
      drawPath(out, pts, static_cast<double>(out.cols) / calib::readGray(inputs[0]).cols);
      std::cout << path_file << ": " << pts.size() << " points drawn\n";
    } else if (!board) {
      cv::cvtColor(out, out, cv::COLOR_BGR2GRAY);
    }
    if (!cv::imwrite(output, out, {cv::IMWRITE_PNG_COMPRESSION, 9})) throw core::InvalidInput(output + ": cannot write");
    std::cout << "wrote " << output << " (" << out.cols << "x" << out.rows << ")\n";
  } catch (const std::exception& e) {
    std::cerr << "tutorial-picture: error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
