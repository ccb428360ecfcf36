// print-board: a calibration board of calib/boards/*.yaml as a printable page at true scale.
//   print-board --board calib/boards/charuco_10x7_25mm.yaml --dpi 300 --output board.png [--pdf board.pdf]
// The PNG is black and white (1 bit), the board drawn by calib::boardTexture (the texture the
// simulator renders, so a printed board and a rendered one are the same pattern) with a white margin
// and a caption; its pHYs chunk records the resolution, so viewers and printers know the size. The
// PDF page is the same image placed at that size (its pixel data is the PNG's own compressed stream,
// which PDF reads with the PNG predictors: no extra library). Print at 100 % ("actual size", no fit to
// page), then measure the span the tool prints and use the measured square size in the board file.
#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdint>
#include <iomanip>
#include <iostream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "tool_common.h"
#include "viewline/core/version.h"
#include "viewline/calib/render.h"
#include "viewline/io/files.h"

namespace {

std::uint32_t crc32(const std::string& bytes) {  // PNG's CRC (ISO 3309), bitwise: a few hundred bytes only
  std::uint32_t c = 0xffffffffu;
  for (const unsigned char b : bytes) {
    c ^= b;
    for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0xedb88320u & (0u - (c & 1u)));
  }
  return c ^ 0xffffffffu;
}

std::string be32(std::uint32_t v) {
  return {static_cast<char>(v >> 24), static_cast<char>(v >> 16), static_cast<char>(v >> 8), static_cast<char>(v)};
}

std::uint32_t readBe32(const std::string& s, std::size_t at) {
  return (std::uint32_t(static_cast<unsigned char>(s[at])) << 24) | (std::uint32_t(static_cast<unsigned char>(s[at + 1])) << 16) |
         (std::uint32_t(static_cast<unsigned char>(s[at + 2])) << 8) | std::uint32_t(static_cast<unsigned char>(s[at + 3]));
}

/// PNG bytes with a pHYs chunk (pixels per metre) after IHDR.
std::string withResolution(const std::string& png, double dpi) {
  const auto ppm = static_cast<std::uint32_t>(std::lround(dpi / 0.0254));
  const std::string body = "pHYs" + be32(ppm) + be32(ppm) + std::string(1, '\1');
  const std::size_t after_ihdr = 8 + 4 + 4 + 13 + 4;
  return png.substr(0, after_ihdr) + be32(9) + body + be32(crc32(body)) + png.substr(after_ihdr);
}

/// The concatenated IDAT data of a PNG: a zlib stream of PNG-filtered rows.
std::string idat(const std::string& png) {
  std::string data;
  for (std::size_t at = 8; at + 8 <= png.size();) {
    const std::uint32_t len = readBe32(png, at);
    if (png.compare(at + 4, 4, "IDAT") == 0) data += png.substr(at + 8, len);
    at += 12 + len;
  }
  return data;
}

/// One-page PDF showing a 1-bit PNG at `dpi`.
std::string pdfPage(const std::string& png, int w, int h, double dpi) {
  const std::string img = idat(png);
  std::ostringstream wpt, hpt;
  wpt << std::fixed << std::setprecision(3) << w * 72.0 / dpi;
  hpt << std::fixed << std::setprecision(3) << h * 72.0 / dpi;
  const std::string content = "q " + wpt.str() + " 0 0 " + hpt.str() + " 0 0 cm /Im0 Do Q\n";
  std::vector<std::string> objs{
      "<< /Type /Catalog /Pages 2 0 R >>",
      "<< /Type /Pages /Kids [3 0 R] /Count 1 >>",
      "<< /Type /Page /Parent 2 0 R /MediaBox [0 0 " + wpt.str() + " " + hpt.str() +
          "] /Resources << /XObject << /Im0 4 0 R >> >> /Contents 5 0 R >>",
      "<< /Type /XObject /Subtype /Image /Width " + std::to_string(w) + " /Height " + std::to_string(h) +
          " /ColorSpace /DeviceGray /BitsPerComponent 1 /Filter /FlateDecode /DecodeParms << /Predictor 15 /Colors 1"
          " /BitsPerComponent 1 /Columns " + std::to_string(w) + " >> /Length " + std::to_string(img.size()) +
          " >>\nstream\n" + img + "\nendstream",
      "<< /Length " + std::to_string(content.size()) + " >>\nstream\n" + content + "endstream"};
  std::string out = "%PDF-1.4\n%\xe2\xe3\xcf\xd3\n";
  std::vector<std::size_t> offsets;
  for (std::size_t i = 0; i < objs.size(); ++i) {
    offsets.push_back(out.size());
    out += std::to_string(i + 1) + " 0 obj\n" + objs[i] + "\nendobj\n";
  }
  const std::size_t xref = out.size();
  out += "xref\n0 " + std::to_string(objs.size() + 1) + "\n0000000000 65535 f \n";
  for (const std::size_t o : offsets) {
    std::ostringstream e;
    e << std::setw(10) << std::setfill('0') << o << " 00000 n \n";
    out += e.str();
  }
  out += "trailer\n<< /Size " + std::to_string(objs.size() + 1) + " /Root 1 0 R >>\nstartxref\n" + std::to_string(xref) + "\n%%EOF\n";
  return out;
}

std::string mm(double metres) {
  std::ostringstream os;
  os << std::fixed << std::setprecision(1) << metres * 1e3 << " mm";
  return os.str();
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Writes a calibration board as a printable PNG (and PDF) at true scale."};
  app.set_version_flag("--version", std::string("viewline ") + viewline::core::kVersion);
  std::string board_file, output, pdf;
  double dpi = 300.0, margin_mm = 15.0;
  app.add_option("--board", board_file, "board description (calib/boards/*.yaml)")->required()->check(CLI::ExistingFile);
  app.add_option("--output", output, "PNG file to write")->required();
  app.add_option("--pdf", pdf, "also write this one-page PDF");
  app.add_option("--dpi", dpi, "printer resolution, dots per inch")->check(CLI::Range(50.0, 1200.0));
  app.add_option("--margin", margin_mm, "white margin around the board, mm (the caption goes in the bottom one)")
      ->check(CLI::Range(8.0, 100.0));
  if (const auto code = viewline::calib::tools::parseCommandLine(app, argc, argv)) return *code;
  return viewline::calib::tools::runTool("print-board", [&] {
    using namespace viewline;
    const calib::BoardSpec board = calib::loadBoard(board_file);
    const double ppm = dpi / 0.0254;
    cv::Point2d origin;
    const cv::Mat tex = calib::boardTexture(board, ppm, origin);
    const int margin = static_cast<int>(std::lround(margin_mm * 1e-3 * ppm));
    cv::Mat page(tex.rows + 2 * margin, tex.cols + 2 * margin, CV_8UC1, cv::Scalar(255));
    tex.copyTo(page(cv::Rect(margin, margin, tex.cols, tex.rows)));

    // What to measure after printing: the longest span of the pattern along its width.
    std::string span;
    const double s = board.spacing;
    switch (board.type) {
      case calib::BoardType::Chessboard:
        span = std::to_string(board.cols + 1) + " squares = " + mm((board.cols + 1) * s);
        break;
      case calib::BoardType::ChArUco:
        span = std::to_string(board.cols) + " squares = " + mm(board.cols * s) + ", marker " + mm(board.marker_size);
        break;
      case calib::BoardType::CirclesGrid:
        span = "centres of the first and last circle of a row " + mm((board.cols - 1) * s);
        break;
      case calib::BoardType::AsymmetricCirclesGrid:
        span = "centres of the first and last circle of a row " + mm(2 * (board.cols - 1) * s);
        break;
      case calib::BoardType::AprilTagGrid:
        span = "tag " + mm(board.tag_size) + " (black square), tag centres " + mm(s) + " apart";
        break;
      case calib::BoardType::AprilTag:
        span = "tag " + mm(board.tag_size) + " (black square)";
        break;
    }
    const double page_w = page.cols / ppm, page_h = page.rows / ppm;
    const std::string lines[2] = {board.describe(),
                                  "print at 100 % (actual size, no fit to page), " + std::to_string(static_cast<int>(dpi)) +
                                      " dpi; measure: " + span};
    // Caption: text 2.5 mm high in the bottom margin (Hershey simplex is about 22 px high at scale 1).
    const double font = 2.5e-3 * ppm / 22.0;
    const int thick = std::max(1, static_cast<int>(std::lround(font * 1.5)));
    for (int k = 0; k < 2; ++k) {
      const int y = tex.rows + margin + static_cast<int>(std::lround((4.0 + 4.0 * k) * 1e-3 * ppm));
      cv::putText(page, lines[k], cv::Point(margin, y), cv::FONT_HERSHEY_SIMPLEX, font, cv::Scalar(0), thick, cv::LINE_8);
    }
    cv::Mat bw;
    cv::threshold(page, bw, 127, 255, cv::THRESH_BINARY);
    std::vector<unsigned char> buf;
    if (!cv::imencode(".png", bw, buf, {cv::IMWRITE_PNG_BILEVEL, 1, cv::IMWRITE_PNG_COMPRESSION, 9}))
      throw core::InvalidInput(output + ": cannot encode the PNG");
    const std::string png(buf.begin(), buf.end());
    io::writeTextFileAtomic(output, withResolution(png, dpi));
    std::cout << "board: " << board.describe() << "\n"
              << "wrote " << output << ": " << page.cols << " x " << page.rows << " px at " << dpi << " dpi = " << mm(page_w)
              << " x " << mm(page_h) << "\n";
    if (!pdf.empty()) {
      io::writeTextFileAtomic(pdf, pdfPage(png, page.cols, page.rows, dpi));
      std::cout << "wrote " << pdf << ": one page of " << mm(page_w) << " x " << mm(page_h) << "\n";
    }
    if (page_w > 0.297 || page_h > 0.210)
      std::cout << "note: larger than an A4 page in landscape (297 x 210 mm): print on a larger sheet or as a poster\n";
    std::cout << "print at 100 % scale, then measure: " << span << "\n";
    return 0;
  });
}
