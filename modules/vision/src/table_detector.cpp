#include "viewline/vision/table_detector.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "viewline/core/checks.h"
#include "viewline/core/error.h"
#include "viewline/core/frames.h"

namespace viewline::vision {

namespace {

cv::Mat ellipseKernel(int size) {
  if (size <= 1) return {};
  return cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(size, size));
}

void requireOddKernel(int size, const char* field) {
  if (size < 1 || size > 31 || size % 2 == 0)
    throw core::InvalidInput(std::string("TableDetectorConfig.") + field + " = " +
                             std::to_string(size) + " must be odd in [1, 31]");
}

/// Index of the contour with the largest area, or -1.
int largestContour(const std::vector<std::vector<cv::Point>>& contours, double* area_out) {
  int best = -1;
  double best_area = -1.0;
  for (std::size_t i = 0; i < contours.size(); ++i) {
    const double a = cv::contourArea(contours[i]);
    if (a > best_area) {
      best_area = a;
      best = static_cast<int>(i);
    }
  }
  if (area_out) *area_out = best_area;
  return best;
}

Eigen::Vector2d lineIntersection(const Eigen::Vector2d& p1, const Eigen::Vector2d& d1,
                                 const Eigen::Vector2d& p2, const Eigen::Vector2d& d2, bool& ok) {
  Eigen::Matrix2d A;
  A.col(0) = d1;
  A.col(1) = -d2;
  const double det = A.determinant();
  ok = std::abs(det) > 1e-9;
  if (!ok) return p1;
  const Eigen::Vector2d t = A.inverse() * (p2 - p1);
  return p1 + t(0) * d1;
}

/// Production refinement of [M]'s corners: each side re-fitted by least squares to the contour
/// pixels along its middle 80 % (away from the ball), moved out by the contour-to-edge offset,
/// and adjacent sides re-intersected. Corners are kept when a side has too few points.
std::array<Eigen::Vector2d, 4> refineCorners(const std::array<Eigen::Vector2d, 4>& ordered,
                                             const std::vector<cv::Point>& contour,
                                             const std::optional<Circle>& ball,
                                             const TableDetectorConfig& cfg) {
  Eigen::Vector2d centroid = Eigen::Vector2d::Zero();
  for (const auto& c : ordered) centroid += 0.25 * c;
  std::array<Eigen::Vector2d, 4> line_p, line_d;
  std::array<bool, 4> fitted{};
  std::vector<cv::Point2f> pts;
  for (std::size_t k = 0; k < 4; ++k) {
    const Eigen::Vector2d a = ordered[k], b = ordered[(k + 1) % 4];
    const double len = (b - a).norm();
    line_p[k] = a;
    line_d[k] = (b - a) / std::max(len, 1e-9);
    if (len < 8.0) continue;
    const Eigen::Vector2d dir = line_d[k];
    const Eigen::Vector2d nrm(-dir.y(), dir.x());
    pts.clear();
    for (const auto& q : contour) {
      const Eigen::Vector2d p(q.x, q.y);
      const double s = (p - a).dot(dir) / len;
      if (s < 0.1 || s > 0.9) continue;
      if (std::abs((p - a).dot(nrm)) > 3.0) continue;
      if (ball && (p - ball->center).norm() < cfg.corners.ball_exclusion_factor * ball->radius + 2.0)
        continue;
      pts.emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()));
    }
    if (pts.size() < 6) continue;
    cv::Vec4f l;
    cv::fitLine(pts, l, cv::DIST_L2, 0, 0.01, 0.01);
    Eigen::Vector2d d(static_cast<double>(l[0]), static_cast<double>(l[1]));
    Eigen::Vector2d p(static_cast<double>(l[2]), static_cast<double>(l[3]));
    Eigen::Vector2d n(-d.y(), d.x());
    if (n.dot(p - centroid) < 0.0) n = -n;  // outward normal
    line_p[k] = p + cfg.edge_offset_px * n;
    line_d[k] = d;
    fitted[k] = true;
  }
  std::array<Eigen::Vector2d, 4> out = ordered;
  for (std::size_t k = 0; k < 4; ++k) {
    // Corner k joins side k-1 (ending at corner k) and side k (starting there).
    const std::size_t prev = (k + 3) % 4;
    if (!fitted[k] && !fitted[prev]) continue;
    bool ok = false;
    const Eigen::Vector2d c = lineIntersection(line_p[prev], line_d[prev], line_p[k], line_d[k], ok);
    if (ok && (c - ordered[k]).norm() < 5.0) out[k] = c;
  }
  return out;
}

/// Ball circle: [M]'s minimum enclosing circle, or (refine) a least-squares ellipse fit whose
/// semi-major axis is the radius of the ellipse's minimum enclosing circle.
std::optional<Circle> ballCircle(const std::vector<cv::Point>& contour, bool refine,
                                 double edge_offset) {
  if (contour.empty()) return std::nullopt;
  Circle c;
  if (refine && contour.size() >= 8) {
    const cv::RotatedRect e = cv::fitEllipse(contour);
    const double a = 0.5 * static_cast<double>(std::max(e.size.width, e.size.height));
    if (std::isfinite(a) && a > 0.0) {
      c.center = {static_cast<double>(e.center.x), static_cast<double>(e.center.y)};
      c.radius = a + edge_offset;
      return c;
    }
  }
  cv::Point2f center;
  float radius = 0.0F;
  cv::minEnclosingCircle(contour, center, radius);
  c.center = {static_cast<double>(center.x), static_cast<double>(center.y)};
  c.radius = static_cast<double>(radius) + (refine ? edge_offset : 0.0);
  return c;
}

/// The cheap part shared by the reference and the production pipeline: from the table contour
/// and the ball contour to the measurements.
TableScene finishScene(const std::vector<cv::Point>* table_contour, double table_area,
                       const std::vector<cv::Point>* ball_contour, double ball_area,
                       const cv::Size& image_size, core::Timestamp stamp, const core::Camera& camera,
                       const TableDetectorConfig& cfg, bool refine,
                       const std::optional<Eigen::Isometry3d>& prior, bool used_roi) {
  TableScene scene;
  const cv::Rect frame(0, 0, image_size.width, image_size.height);
  // Ball in the image.
  bool ball_clipped = false;
  if (ball_contour && ball_area + 0.5 * cv::arcLength(*ball_contour, true) >= cfg.min_ball_area_px) {
    ball_clipped = touchesBorder(cv::boundingRect(*ball_contour), frame);
    scene.ball_circle = ballCircle(*ball_contour, refine, cfg.edge_offset_px);
  }
  // Table.
  if (!table_contour) {
    scene.table = Result<TableMeasurement>::fail(FailureReason::NotFound, "no red table surface");
  } else if (table_area < cfg.min_table_area_px) {
    scene.table = Result<TableMeasurement>::fail(
        FailureReason::TooSmall, "red area " + std::to_string(table_area) + " px < min_table_area_px");
  } else if (touchesBorder(cv::boundingRect(*table_contour), frame)) {
    scene.table = Result<TableMeasurement>::fail(
        FailureReason::Clipped, "table touches the image border: its corners cannot all be seen");
  } else {
    const auto corners = findTableCorners(*table_contour, ball_clipped ? std::nullopt : scene.ball_circle,
                                          image_size.width, cfg.corners);
    if (!corners) {
      scene.table = corners.failure();
    } else {
      auto ordered = orderTableCorners(corners->corners);
      if (refine) ordered = refineCorners(ordered, *table_contour, scene.ball_circle, cfg);
      const auto pose = solveTablePose(ordered, camera, cfg.side_m, refine, prior);
      if (!pose) {
        scene.table = pose.failure();
      } else {
        TableMeasurement m;
        m.stamp = stamp;
        m.c_M_t = pose->c_M_t;
        m.corners = pose->corners;
        m.reprojection_rms_px = pose->reprojection_rms_px;
        m.pixel = Eigen::Vector2d::Zero();
        for (const auto& c : m.corners) m.pixel += 0.25 * c;
        // Mean of four corners with independent noise σc: var = σc² / 4.
        m.pixel_covariance = Eigen::Matrix2d::Identity() * (cfg.corner_sigma_px * cfg.corner_sigma_px / 4.0);
        const double rms_limit = 2.0;
        m.quality = m.reprojection_rms_px < rms_limit ? Quality::Good : Quality::Degraded;
        m.score = 1.0 / (1.0 + m.reprojection_rms_px);
        m.used_roi = used_roi;
        scene.table = m;
      }
    }
  }
  // Ball on the table.
  if (!scene.ball_circle) {
    scene.ball = Result<BallOnTableMeasurement>::fail(
        ball_contour ? FailureReason::TooSmall : FailureReason::NotFound,
        ball_contour ? "green blob below min_ball_area_px" : "no green ball");
  } else if (ball_clipped) {
    scene.ball = Result<BallOnTableMeasurement>::fail(FailureReason::Clipped,
                                                      "ball touches the image border");
  } else if (!scene.table) {
    scene.ball = Result<BallOnTableMeasurement>::fail(
        FailureReason::NoReference, std::string("no table pose (") + toString(scene.table.failure().reason) + ")");
  } else {
    BallOnTableMeasurement b;
    b.stamp = stamp;
    b.circle = *scene.ball_circle;
    b.pixel = b.circle.center;
    const double var = cfg.ball_edge_noise_px * cfg.ball_edge_noise_px / (core::kPi * b.circle.radius);
    b.pixel_covariance = Eigen::Matrix2d::Identity() * var;
    b.known_radius = ballOnTableKnownRadius(camera, b.circle, scene.table->c_M_t, cfg.ball_radius_m);
    b.unknown_radius = ballOnTableUnknownRadius(camera, b.circle, scene.table->c_M_t);
    const double roundness =
        std::min(1.0, ball_area / (core::kPi * b.circle.radius * b.circle.radius) + 1e-12);
    b.quality = roundness > 0.6 ? Quality::Good : Quality::Degraded;
    b.score = roundness;
    scene.ball = b;
  }
  return scene;
}

}  // namespace

void TableDetectorConfig::validate() const {
  core::requirePositive(side_m, "TableDetectorConfig.side_m");
  core::requirePositive(ball_radius_m, "TableDetectorConfig.ball_radius_m");
  requireOddKernel(blur_ksize, "blur_ksize");
  requireOddKernel(open_kernel_px, "open_kernel_px");
  requireOddKernel(close_kernel_px, "close_kernel_px");
  requireOddKernel(ball_open_kernel_px, "ball_open_kernel_px");
  red_hls.validate("TableDetectorConfig.red_hls");
  green_hls.validate("TableDetectorConfig.green_hls");
  if (!(corners.approx_epsilon_fraction > 0.0 && corners.approx_epsilon_fraction < 0.2))
    throw core::InvalidInput("TableDetectorConfig.corners.approx_epsilon_fraction must be in (0, 0.2)");
  if (!(corners.ball_exclusion_factor >= 0.0))
    throw core::InvalidInput("TableDetectorConfig.corners.ball_exclusion_factor must be >= 0");
  core::requirePositive(corners.max_ta_tb, "TableDetectorConfig.corners.max_ta_tb");
  core::requirePositive(min_table_area_px, "TableDetectorConfig.min_table_area_px");
  core::requirePositive(min_ball_area_px, "TableDetectorConfig.min_ball_area_px");
  if (!(roi_margin_fraction >= 0.0 && roi_margin_fraction <= 2.0))
    throw core::InvalidInput("TableDetectorConfig.roi_margin_fraction must be in [0, 2]");
  if (roi_margin_px < 0) throw core::InvalidInput("TableDetectorConfig.roi_margin_px must be >= 0");
  core::requireFinite(edge_offset_px, "TableDetectorConfig.edge_offset_px");
  core::requirePositive(corner_sigma_px, "TableDetectorConfig.corner_sigma_px");
  core::requirePositive(ball_edge_noise_px, "TableDetectorConfig.ball_edge_noise_px");
}

TableDetector::TableDetector(core::Camera camera, TableDetectorConfig config)
    : camera_(std::move(camera)), config_(std::move(config)) {
  config_.validate();
  if (camera_.width == 0 || camera_.height == 0)
    throw core::InvalidInput("TableDetector: camera width/height must be > 0");
  open_kernel_ = ellipseKernel(config_.open_kernel_px);
  close_kernel_ = ellipseKernel(config_.close_kernel_px);
  ball_kernel_ = ellipseKernel(config_.ball_open_kernel_px);
  // One pass classifies every HLS pixel: bit 0 = red, bit 1 = green (bit-exact with inRange).
  const auto& r = config_.red_hls;
  const auto& g = config_.green_hls;
  for (int v = 0; v < 256; ++v) {
    const auto in_hue = [v](const ColorRange& c) {
      return v <= 179 && (c.wraps() ? (v >= c.hue_lo || v <= c.hue_hi) : (v >= c.hue_lo && v <= c.hue_hi));
    };
    const auto i = static_cast<std::size_t>(v);
    lut_h_[i] = static_cast<unsigned char>((in_hue(r) ? 1 : 0) | (in_hue(g) ? 2 : 0));
    lut_l_[i] = static_cast<unsigned char>((v >= r.c1_lo && v <= r.c1_hi ? 1 : 0) |
                                           (v >= g.c1_lo && v <= g.c1_hi ? 2 : 0));
    lut_s_[i] = static_cast<unsigned char>((v >= r.c2_lo && v <= r.c2_hi ? 1 : 0) |
                                           (v >= g.c2_lo && v <= g.c2_hi ? 2 : 0));
  }
}

void TableDetector::reset() {
  window_.reset();
  prior_.reset();
}

bool TableDetector::processWindow(const cv::Mat& bgr, const cv::Rect& roi) {
  const cv::Mat view = bgr(roi);
  const int k = config_.blur_ksize;
  if (k > 1)
    cv::GaussianBlur(view, blurred_, cv::Size(k, k), 0.0);  // reads the parent image around the window
  else
    view.copyTo(blurred_);
  cv::cvtColor(blurred_, hls_, cv::COLOR_BGR2HLS);
  red_.create(roi.size(), CV_8UC1);
  green_.create(roi.size(), CV_8UC1);
  for (int y = 0; y < roi.height; ++y) {
    const unsigned char* p = hls_.ptr<unsigned char>(y);
    unsigned char* rr = red_.ptr<unsigned char>(y);
    unsigned char* gg = green_.ptr<unsigned char>(y);
    for (int x = 0; x < roi.width; ++x, p += 3) {
      const unsigned c = lut_h_[p[0]] & lut_l_[p[1]] & lut_s_[p[2]];
      rr[x] = (c & 1U) ? 255 : 0;
      gg[x] = (c & 2U) ? 255 : 0;
    }
  }
  if (!open_kernel_.empty()) cv::morphologyEx(red_, red_, cv::MORPH_OPEN, open_kernel_);
  if (!close_kernel_.empty()) cv::morphologyEx(red_, red_, cv::MORPH_CLOSE, close_kernel_);
  if (!ball_kernel_.empty()) cv::morphologyEx(green_, green_, cv::MORPH_OPEN, ball_kernel_);
  cv::findContours(red_, contours_, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_NONE, roi.tl());
  cv::findContours(green_, ball_contours_, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_NONE, roi.tl());
  const cv::Rect full(0, 0, bgr.cols, bgr.rows);
  if (roi != full) {
    // The window must contain the whole table: a contour cut by the window (but not by the image)
    // means the table moved out of it.
    double area = 0.0;
    const int t = largestContour(contours_, &area);
    if (t < 0) return false;
    const cv::Rect box = cv::boundingRect(contours_[static_cast<std::size_t>(t)]);
    const bool cut = (box.x <= roi.x && roi.x > 0) || (box.y <= roi.y && roi.y > 0) ||
                     (box.x + box.width >= roi.x + roi.width && roi.x + roi.width < full.width) ||
                     (box.y + box.height >= roi.y + roi.height && roi.y + roi.height < full.height);
    if (cut) return false;
  }
  return true;
}

TableScene TableDetector::detect(const cv::Mat& bgr, core::Timestamp stamp) {
  requireBgrImage(bgr, "TableDetector::detect");
  core::requireFinite(stamp, "TableDetector::detect: stamp");
  if (static_cast<unsigned>(bgr.cols) != camera_.width || static_cast<unsigned>(bgr.rows) != camera_.height)
    throw core::InvalidInput("TableDetector::detect: image is " + std::to_string(bgr.cols) + "x" +
                             std::to_string(bgr.rows) + ", camera '" + camera_.name + "' is " +
                             std::to_string(camera_.width) + "x" + std::to_string(camera_.height));
  const cv::Rect full(0, 0, bgr.cols, bgr.rows);
  bool used_roi = false;
  if (window_ && processWindow(bgr, *window_)) {
    used_roi = *window_ != full;
  } else {
    processWindow(bgr, full);
  }
  double table_area = 0.0, ball_area = 0.0;
  const int t = largestContour(contours_, &table_area);
  const int b = largestContour(ball_contours_, &ball_area);
  const auto* table_contour = t >= 0 ? &contours_[static_cast<std::size_t>(t)] : nullptr;
  const auto* ball_contour = b >= 0 ? &ball_contours_[static_cast<std::size_t>(b)] : nullptr;
  TableScene scene = finishScene(table_contour, table_area, ball_contour, ball_area, bgr.size(), stamp,
                                 camera_, config_, config_.refine, prior_, used_roi);
  if (scene.table) {
    prior_ = scene.table->c_M_t;
    cv::Rect box = cv::boundingRect(*table_contour);
    if (scene.ball_circle) {
      const auto& c = *scene.ball_circle;
      box |= squareRoi(c.center.x(), c.center.y(), c.radius + 2.0, bgr.size());
    }
    const int mx = static_cast<int>(config_.roi_margin_fraction * box.width) + config_.roi_margin_px;
    const int my = static_cast<int>(config_.roi_margin_fraction * box.height) + config_.roi_margin_px;
    window_ = cv::Rect(box.x - mx, box.y - my, box.width + 2 * mx, box.height + 2 * my) & full;
  } else {
    window_.reset();
  }
  return scene;
}

TableScene referenceTableScene(const cv::Mat& bgr, core::Timestamp stamp, const core::Camera& camera,
                               const TableDetectorConfig& config,
                               const std::optional<Eigen::Isometry3d>& prior) {
  requireBgrImage(bgr, "referenceTableScene");
  config.validate();
  // Written as [M]'s Python does it: every step on the full frame, new buffers each call.
  cv::Mat blurred, hls, red, green;
  cv::GaussianBlur(bgr, blurred, cv::Size(config.blur_ksize, config.blur_ksize), 0.0);
  cv::cvtColor(blurred, hls, cv::COLOR_BGR2HLS);
  thresholdColor(hls, config.red_hls, red);
  if (config.open_kernel_px > 1)
    cv::morphologyEx(red, red, cv::MORPH_OPEN, ellipseKernel(config.open_kernel_px));
  if (config.close_kernel_px > 1)
    cv::morphologyEx(red, red, cv::MORPH_CLOSE, ellipseKernel(config.close_kernel_px));
  std::vector<std::vector<cv::Point>> contours;
  cv::findContours(red, contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_SIMPLE);
  thresholdColor(hls, config.green_hls, green);
  if (config.ball_open_kernel_px > 1)
    cv::morphologyEx(green, green, cv::MORPH_OPEN, ellipseKernel(config.ball_open_kernel_px));
  std::vector<std::vector<cv::Point>> ball_contours;
  cv::findContours(green, ball_contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_SIMPLE);
  double table_area = 0.0, ball_area = 0.0;
  const int t = largestContour(contours, &table_area);
  const int b = largestContour(ball_contours, &ball_area);
  return finishScene(t >= 0 ? &contours[static_cast<std::size_t>(t)] : nullptr, table_area,
                     b >= 0 ? &ball_contours[static_cast<std::size_t>(b)] : nullptr, ball_area, bgr.size(),
                     stamp, camera, config, /*refine=*/false, prior, false);
}

}  // namespace viewline::vision
