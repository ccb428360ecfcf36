#include "viewline/calib/render.h"

#include <apriltag/apriltag.h>
#include <apriltag/tag16h5.h>
#include <apriltag/tag25h9.h>
#include <apriltag/tag36h11.h>
#include <apriltag/tagCircle21h7.h>
#include <cmath>
#include <cstdlib>
#include <opencv2/imgproc.hpp>

#include "viewline/calib/extrinsics.h"
#include "viewline/core/error.h"

namespace viewline::calib {
namespace {

// The tag's image, black border included (the family's white outer module cropped), 8-bit.
cv::Mat tagImage(const std::string& fam, int id) {
  apriltag_family_t* f = nullptr;
  if (fam == "36h11") f = tag36h11_create();
  else if (fam == "25h9") f = tag25h9_create();
  else if (fam == "16h5") f = tag16h5_create();
  else if (fam == "circle21h7") f = tagCircle21h7_create();
  else throw core::InvalidInput("tag_family '" + fam + "' cannot be rendered");
  if (id < 0 || static_cast<unsigned>(id) >= f->ncodes) throw core::InvalidInput("tag id " + std::to_string(id) + " not in family " + fam);
  image_u8_t* im = apriltag_to_image(f, id);
  const int border = (f->total_width - f->width_at_border) / 2;
  cv::Mat full(im->height, im->width, CV_8UC1, im->buf, static_cast<std::size_t>(im->stride));
  cv::Mat out = full(cv::Rect(border, border, f->width_at_border, f->width_at_border)).clone();
  // image_u8_destroy is not exported by every build of libapriltag; it frees exactly these two.
  std::free(im->buf);
  std::free(im);
  if (fam == "36h11") tag36h11_destroy(f);
  else if (fam == "25h9") tag25h9_destroy(f);
  else if (fam == "16h5") tag16h5_destroy(f);
  else tagCircle21h7_destroy(f);
  return out;
}

}  // namespace

cv::Mat boardTexture(const BoardSpec& board, double ppm, cv::Point2d& origin) {
  board.validate();
  const bool single = board.type == BoardType::AprilTag;
  const double unit = single ? board.tag_size : board.spacing;
  double x0 = -unit, y0 = -unit, x1 = 0, y1 = 0;
  if (single) {
    x0 = y0 = -board.tag_size;
    x1 = y1 = board.tag_size;
  } else {
    // charuco: cols x rows squares around (cols - 1) x (rows - 1) inner corners.
    const int inner = board.type == BoardType::ChArUco ? 1 : 0;
    const double w = board.type == BoardType::AsymmetricCirclesGrid ? (2 * board.cols - 1) * board.spacing
                                                                     : (board.cols - 1 - inner) * board.spacing;
    x1 = w + unit;
    y1 = (board.rows - 1 - inner) * board.spacing + unit;
  }
  origin = {x0, y0};
  const int W = static_cast<int>(std::ceil((x1 - x0) * ppm)), H = static_cast<int>(std::ceil((y1 - y0) * ppm));
  cv::Mat tex(H, W, CV_8UC1, cv::Scalar(255));
  auto px = [&](double x, double y) { return cv::Point2d((x - x0) * ppm, (y - y0) * ppm); };
  const double s = board.spacing;
  switch (board.type) {
    case BoardType::Chessboard:
      for (int j = -1; j < board.rows; ++j)
        for (int i = -1; i < board.cols; ++i)
          if (((i + j) & 1) == 0) {
            const cv::Point2d a = px(i * s, j * s), b = px((i + 1) * s, (j + 1) * s);
            cv::rectangle(tex, cv::Point(static_cast<int>(std::lround(a.x)), static_cast<int>(std::lround(a.y))),
                          cv::Point(static_cast<int>(std::lround(b.x)) - 1, static_cast<int>(std::lround(b.y)) - 1),
                          cv::Scalar(0), cv::FILLED);
          }
      break;
    case BoardType::CirclesGrid:
    case BoardType::AsymmetricCirclesGrid: {
      const double radius = (board.type == BoardType::CirclesGrid ? 0.25 : 0.35) * s * ppm;
      for (const auto& p : board.objectPoints()) {
        const cv::Point2d c = px(p.x, p.y);
        cv::circle(tex, cv::Point(static_cast<int>(c.x * 16), static_cast<int>(c.y * 16)),
                   static_cast<int>(radius * 16), cv::Scalar(0), cv::FILLED, cv::LINE_AA, 4);
      }
      break;
    }
    case BoardType::AprilTagGrid:
    case BoardType::AprilTag: {
      std::vector<std::pair<int, cv::Point2d>> tags;
      if (single) tags.emplace_back(board.tag_ids.empty() ? 0 : board.tag_ids.front(), cv::Point2d(0, 0));
      else
        for (int r = 0; r < board.rows; ++r)
          for (int c = 0; c < board.cols; ++c) tags.emplace_back(board.first_id + r * board.cols + c, cv::Point2d(c * s, r * s));
      for (const auto& [id, centre] : tags) {
        const cv::Mat t = tagImage(board.tag_family, id);
        const cv::Point2d a = px(centre.x - board.tag_size / 2, centre.y - board.tag_size / 2);
        const int n = static_cast<int>(std::lround(board.tag_size * ppm));
        cv::Mat scaled;
        cv::resize(t, scaled, cv::Size(n, n), 0, 0, cv::INTER_NEAREST);
        scaled.copyTo(tex(cv::Rect(static_cast<int>(std::lround(a.x)), static_cast<int>(std::lround(a.y)), n, n)));
      }
      break;
    }
    case BoardType::ChArUco: {
      // OpenCV draws the squares and markers at a whole number of texels per square (exact edges),
      // then the drawing is scaled to the requested resolution (the texture is exactly the squares).
      const int k = std::max(20, static_cast<int>(std::ceil(s * ppm)));
      cv::Mat drawn;
      charucoBoard(board)->draw(cv::Size(board.cols * k, board.rows * k), drawn, 0, 1);
      if (drawn.size() == tex.size()) drawn.copyTo(tex);
      else cv::resize(drawn, tex, tex.size(), 0, 0, cv::INTER_AREA);
      break;
    }
  }
  return tex;
}

cv::Mat renderBoard(const core::Camera& camera, const Eigen::Isometry3d& c_M_o, const BoardSpec& board, core::Rng& rng,
                    const RenderOptions& opt) {
  if (camera.width == 0 || camera.height == 0) throw core::InvalidInput("renderBoard: camera has no image size");
  const int ss = std::max(1, opt.supersample);
  // Texture resolution: about two texels per rendered (supersampled) pixel at the board's distance.
  const double depth = std::max(0.05, c_M_o.translation().z());
  const double ppm = std::clamp(2.0 * ss * camera.focalPx() / depth, 500.0, 20000.0);
  cv::Point2d origin;
  const cv::Mat tex = boardTexture(board, ppm, origin);
  // Board plane z = 0: normalised point m = H (X, Y, 1), H = [r1 r2 t]; inverse maps rays to the plane.
  // A single tag's pose is in ViSP's tag frame (y up, z out of the paper); the texture's is y down.
  Eigen::Isometry3d c_M_tex = c_M_o;
  if (board.type == BoardType::AprilTag) c_M_tex = c_M_o * groundFromBoard(BoardType::Chessboard);
  Eigen::Matrix3d H;
  H.col(0) = c_M_tex.linear().col(0);
  H.col(1) = c_M_tex.linear().col(1);
  H.col(2) = c_M_tex.translation();
  const Eigen::Matrix3d Hinv = H.inverse();
  const int W = static_cast<int>(camera.width) * ss, Ht = static_cast<int>(camera.height) * ss;
  cv::Mat mapx(Ht, W, CV_32FC1), mapy(Ht, W, CV_32FC1);
  for (int v = 0; v < Ht; ++v)
    for (int u = 0; u < W; ++u) {
      const Eigen::Vector2d uv((u + 0.5) / ss - 0.5, (v + 0.5) / ss - 0.5);
      const Eigen::Vector2d xy = camera.pixelToNormalized(uv);
      const Eigen::Vector3d b = Hinv * Eigen::Vector3d(xy.x(), xy.y(), 1.0);
      float mx = -1.f, my = -1.f;
      // b(2) > 0 <=> the ray hits the plane in front of the camera.
      if (b(2) > 1e-12) {
        mx = static_cast<float>((b(0) / b(2) - origin.x) * ppm - 0.5);
        my = static_cast<float>((b(1) / b(2) - origin.y) * ppm - 0.5);
      }
      mapx.at<float>(v, u) = mx;
      mapy.at<float>(v, u) = my;
    }
  cv::Mat big;
  cv::remap(tex, big, mapx, mapy, cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar(opt.background));
  cv::Mat img;
  if (ss > 1) cv::resize(big, img, cv::Size(static_cast<int>(camera.width), static_cast<int>(camera.height)), 0, 0, cv::INTER_AREA);
  else img = big;
  cv::Mat f;
  img.convertTo(f, CV_32F);
  if (opt.blur_sigma_px > 0) cv::GaussianBlur(f, f, cv::Size(0, 0), opt.blur_sigma_px);
  if (opt.noise_sigma > 0) {
    std::normal_distribution<float> n(0.f, static_cast<float>(opt.noise_sigma));
    for (int v = 0; v < f.rows; ++v)
      for (int u = 0; u < f.cols; ++u) f.at<float>(v, u) += n(rng);
  }
  cv::Mat out;
  f.convertTo(out, CV_8U);
  return out;
}

}  // namespace viewline::calib
