#include "viewline/vision/table_detector.h"

#include <algorithm>
#include <cmath>
#include <Eigen/Eigenvalues>
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

/// Bilinear sample of a colour feature of the raw BGR image: kChannel = 2 (red) gives
/// R - max(G, B), kChannel = 1 (green) G - max(R, B). NaN outside the image.
template <int kChannel>
double featureAt(const cv::Mat& bgr, double u, double v) {
  if (!(u >= 0.0 && v >= 0.0 && u <= bgr.cols - 1.001 && v <= bgr.rows - 1.001)) return std::nan("");
  const int x = static_cast<int>(u), y = static_cast<int>(v);
  const double fx = u - x, fy = v - y;
  double f[3] = {0.0, 0.0, 0.0};
  const cv::Vec3b& a = bgr.at<cv::Vec3b>(y, x);
  const cv::Vec3b& b = bgr.at<cv::Vec3b>(y, x + 1);
  const cv::Vec3b& c = bgr.at<cv::Vec3b>(y + 1, x);
  const cv::Vec3b& d = bgr.at<cv::Vec3b>(y + 1, x + 1);
  for (int k = 0; k < 3; ++k)
    f[k] = (1 - fy) * ((1 - fx) * a[k] + fx * b[k]) + fy * ((1 - fx) * c[k] + fx * d[k]);
  const int o1 = (kChannel + 1) % 3, o2 = (kChannel + 2) % 3;
  return f[kChannel] - std::max(f[o1], f[o2]);
}

/// Sub-pixel edge along p(s) = p0 + s n, s in [-reach, reach]: the crossing of the level half
/// way between the inside plateau (first pixel of the profile) and the outside (last pixel),
/// searched from the inside. False without enough contrast or without a crossing.
template <int kChannel>
bool edgeAlong(const cv::Mat& bgr, const Eigen::Vector2d& p0, const Eigen::Vector2d& n, double reach,
               double min_contrast, double& s_edge) {
  constexpr double kStep = 0.25;
  const int count = static_cast<int>(2.0 * reach / kStep) + 1;
  double prof[64];
  if (count > 64 || count < 9) return false;
  // The segment is inside the image when both ends are (the image is convex); the samples are
  // then taken lazily: the plateaus at both ends, the rest only as far as the search needs.
  bool have[64] = {};
  const auto at = [&](int i) {
    if (!have[i]) {
      const Eigen::Vector2d p = p0 + (-reach + i * kStep) * n;
      prof[i] = featureAt<kChannel>(bgr, p.x(), p.y());
      have[i] = true;
    }
    return prof[i];
  };
  if (std::isnan(at(0)) || std::isnan(at(count - 1))) return false;
  const int plateau = 4;  // 1 px
  double in = 0.0, out = 0.0;
  for (int i = 0; i < plateau; ++i) {
    in += at(i);
    out += at(count - 1 - i);
  }
  in /= plateau;
  out /= plateau;
  if (in - out < min_contrast) return false;
  const auto crossing = [&](double level, int from, int to, double& s) {
    for (int i = std::max(from, 0); i + 1 < count && i < to; ++i) {
      if (at(i) >= level && at(i + 1) < level) {
        s = -reach + kStep * (i + (prof[i] - level) / (prof[i] - prof[i + 1]));
        return true;
      }
    }
    return false;
  };
  if (!crossing(0.5 * (in + out), 0, count, s_edge)) return false;
  // Second pass with the levels just beside the edge (1.25 px either side): the plateaus far
  // from it may differ from the edge's own colours (shading of a sphere, texture).
  const int ie = static_cast<int>(std::lround((s_edge + reach) / kStep));
  const int gap = 5;  // 1.25 px: the anti-aliased, bilinearly sampled step spans ±1 px
  if (ie - gap >= 0 && ie + gap < count) {
    const double in2 = at(ie - gap), out2 = at(ie + gap);
    double s2 = 0.0;
    if (in2 - out2 >= min_contrast && crossing(0.5 * (in2 + out2), ie - gap, ie + gap, s2)) s_edge = s2;
  }
  return true;
}

/// Total least-squares line through points (centroid + principal direction), then once more
/// without the points farther than 1 px from the first line (outliers: clutter, the ball).
bool fitLineRobust(std::vector<Eigen::Vector2d>& pts, Eigen::Vector2d& point, Eigen::Vector2d& dir) {
  for (int round = 0; round < 2; ++round) {
    if (pts.size() < 4) return false;
    Eigen::Vector2d mean = Eigen::Vector2d::Zero();
    for (const auto& p : pts) mean += p;
    mean /= static_cast<double>(pts.size());
    Eigen::Matrix2d S = Eigen::Matrix2d::Zero();
    for (const auto& p : pts) S += (p - mean) * (p - mean).transpose();
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(S);
    point = mean;
    dir = es.eigenvectors().col(1);  // largest eigenvalue
    if (round == 0) {
      const Eigen::Vector2d n(-dir.y(), dir.x());
      pts.erase(std::remove_if(pts.begin(), pts.end(), [&](const Eigen::Vector2d& p) { return std::abs((p - mean).dot(n)) > 1.0; }),
                pts.end());
    }
  }
  return true;
}

/// Raised borders ([M]'s table): seen from outside a side, the border's top inner edge hides the
/// surface edge, so the visible red boundary of that side is the 3D line at height h
/// (x or y = ±L/2, z = h), not the surface edge (z = 0); a side whose inner wall faces the
/// camera shows the surface edge. Gauss-Newton on the pose over all sub-pixel edge points, the
/// residual of a point being its distance (normalised image plane) to the projected 3D line of
/// its side; the visibility of each wall is re-decided at every iteration.
Eigen::Isometry3d refinePoseWithBorders(const Eigen::Isometry3d& c_M_t, const std::array<Eigen::Vector2d, 4>& ordered,
                                        const std::array<Eigen::Vector2d, 4>& pose_corners,
                                        const std::array<std::vector<Eigen::Vector2d>, 4>& edges,
                                        const core::Camera& camera, double side, double height) {
  const double h = 0.5 * side;
  const std::array<Eigen::Vector3d, 4> P{Eigen::Vector3d(-h, -h, 0), Eigen::Vector3d(h, -h, 0), Eigen::Vector3d(h, h, 0),
                                         Eigen::Vector3d(-h, h, 0)};
  // Side j of `ordered` runs from object corner a(j) to a(j) + 1 in the pose's frame.
  std::array<int, 4> first{};
  for (int j = 0; j < 4; ++j) {
    int best = 0;
    for (int i = 0; i < 4; ++i)
      if ((pose_corners[static_cast<std::size_t>(i)] - ordered[static_cast<std::size_t>(j)]).norm() <
          (pose_corners[static_cast<std::size_t>(best)] - ordered[static_cast<std::size_t>(j)]).norm())
        best = i;
    first[static_cast<std::size_t>(j)] = best;
  }
  std::vector<std::pair<int, Eigen::Vector3d>> obs;  // (side j, homogeneous normalised point)
  for (int j = 0; j < 4; ++j)
    for (const auto& uv : edges[static_cast<std::size_t>(j)]) {
      const Eigen::Vector2d xy = camera.pixelToNormalized(uv);
      obs.emplace_back(j, Eigen::Vector3d(xy.x(), xy.y(), 1.0));
    }
  if (obs.size() < 12) return c_M_t;
  auto residuals = [&](const Eigen::Isometry3d& M, Eigen::VectorXd& r) {
    const Eigen::Vector3d cam_t = M.inverse().translation();
    std::array<Eigen::Vector3d, 4> lines;
    for (int j = 0; j < 4; ++j) {
      const Eigen::Vector3d A = P[static_cast<std::size_t>(first[static_cast<std::size_t>(j)])];
      const Eigen::Vector3d B = P[static_cast<std::size_t>((first[static_cast<std::size_t>(j)] + 1) % 4)];
      Eigen::Vector3d mid = 0.5 * (A + B);
      const Eigen::Vector3d out(mid.x(), mid.y(), 0.0);  // outward normal of the side (unnormalised)
      const bool wall_faces_camera = (cam_t - mid).dot(out) < 0.0;
      const Eigen::Vector3d dz(0.0, 0.0, wall_faces_camera ? 0.0 : height);
      lines[static_cast<std::size_t>(j)] = (M * (A + dz)).cross(M * (B + dz));
    }
    r.resize(static_cast<Eigen::Index>(obs.size()));
    for (std::size_t i = 0; i < obs.size(); ++i) {
      const Eigen::Vector3d& l = lines[static_cast<std::size_t>(obs[i].first)];
      r(static_cast<Eigen::Index>(i)) = l.dot(obs[i].second) / l.head<2>().norm();
    }
  };
  auto perturb = [](const Eigen::Isometry3d& M, const Eigen::Matrix<double, 6, 1>& d) {
    Eigen::Isometry3d out = M;
    const double a = d.head<3>().norm();
    if (a > 0.0) out.linear() = Eigen::AngleAxisd(a, d.head<3>() / a).toRotationMatrix() * M.linear();
    out.translation() += d.tail<3>();
    return out;
  };
  Eigen::Isometry3d M = c_M_t;
  Eigen::VectorXd r0, r1;
  for (int it = 0; it < 6; ++it) {
    residuals(M, r0);
    Eigen::MatrixXd J(r0.size(), 6);
    for (int k = 0; k < 6; ++k) {
      Eigen::Matrix<double, 6, 1> d = Eigen::Matrix<double, 6, 1>::Zero();
      d(k) = 1e-6;
      residuals(perturb(M, d), r1);
      J.col(k) = (r1 - r0) / 1e-6;
    }
    const Eigen::Matrix<double, 6, 1> step = (J.transpose() * J).ldlt().solve(-J.transpose() * r0);
    if (!step.allFinite()) return c_M_t;
    M = perturb(M, step);
    if (step.norm() < 1e-9) break;
  }
  return M;
}

/// Production refinement of [M]'s corners: sub-pixel edge points of the red surface sampled
/// along each side (middle 80 %, away from the ball) on the raw image, a robust line fit per
/// side (up to 33 edge points), adjacent sides re-intersected. A side with too few edge points keeps its line.
std::array<Eigen::Vector2d, 4> refineCorners(const cv::Mat& bgr, const std::array<Eigen::Vector2d, 4>& ordered,
                                             const std::optional<Circle>& ball,
                                             const TableDetectorConfig& cfg,
                                             std::array<std::vector<Eigen::Vector2d>, 4>* edge_points) {
  std::array<Eigen::Vector2d, 4> corners = ordered;
  std::vector<Eigen::Vector2d> pts;
  for (int pass = 0; pass < 1; ++pass) {
    Eigen::Vector2d centroid = Eigen::Vector2d::Zero();
    for (const auto& c : corners) centroid += 0.25 * c;
    std::array<Eigen::Vector2d, 4> line_p, line_d;
    std::array<bool, 4> fitted{};
    for (std::size_t k = 0; k < 4; ++k) {
      const Eigen::Vector2d a = corners[k], b = corners[(k + 1) % 4];
      const double len = (b - a).norm();
      line_p[k] = a;
      line_d[k] = (b - a) / std::max(len, 1e-9);
      if (len < 8.0) continue;
      Eigen::Vector2d n(-line_d[k].y(), line_d[k].x());
      if (n.dot(a - centroid) < 0.0) n = -n;  // outward
      pts.clear();
      const int samples = std::clamp(static_cast<int>(len / 2.0), 4, 32);  // cost bound
      for (int i = 0; i <= samples; ++i) {
        const double s = 0.1 + 0.8 * i / std::max(samples, 1);
        const Eigen::Vector2d p = a + s * (b - a);
        if (ball && (p - ball->center).norm() < cfg.corners.ball_exclusion_factor * ball->radius + 4.0) continue;
        double e = 0.0;
        if (!edgeAlong<2>(bgr, p, n, 4.0, 25.0, e)) continue;
        pts.push_back(p + e * n);
      }
      if (pts.size() < 6) continue;
      fitted[k] = fitLineRobust(pts, line_p[k], line_d[k]);
      if (edge_points) (*edge_points)[k] = pts;  // inliers of the line fit
    }
    std::array<Eigen::Vector2d, 4> next = corners;
    for (std::size_t k = 0; k < 4; ++k) {
      // Corner k joins side k-1 (ending at corner k) and side k (starting there).
      const std::size_t prev = (k + 3) % 4;
      if (!fitted[k] && !fitted[prev]) continue;
      bool ok = false;
      const Eigen::Vector2d c = lineIntersection(line_p[prev], line_d[prev], line_p[k], line_d[k], ok);
      if (ok && (c - ordered[k]).norm() < 6.0) next[k] = c;
    }
    corners = next;
  }
  return corners;
}

/// Production refinement of the ball circle: sub-pixel edge points of the green ball on 32 rays
/// from its centre, a least-squares ellipse through them; centre = ellipse centre, radius = its
/// semi-major axis (the minimum enclosing circle of the true outline, which [M]'s step
/// approximates from pixel contours). Kept as is when too many rays find no edge (occlusion).
Circle refineBallCircle(const cv::Mat& bgr, const Circle& initial) {
  std::vector<cv::Point2f> pts;
  constexpr int kRays = 32;
  const double reach = std::min(4.0, std::max(2.0, 0.45 * initial.radius));
  for (int i = 0; i < kRays; ++i) {
    const double th = 2.0 * core::kPi * i / kRays;
    const Eigen::Vector2d n(std::cos(th), std::sin(th));
    const Eigen::Vector2d p = initial.center + initial.radius * n;
    double e = 0.0;
    if (!edgeAlong<1>(bgr, p, n, reach, 25.0, e)) continue;
    const Eigen::Vector2d q = p + e * n;
    pts.emplace_back(static_cast<float>(q.x()), static_cast<float>(q.y()));
  }
  if (pts.size() < 24) return initial;  // occluded or clipped: keep [M]'s circle
  const cv::RotatedRect el = cv::fitEllipse(pts);
  const double a = 0.5 * static_cast<double>(std::max(el.size.width, el.size.height));
  const Eigen::Vector2d c(static_cast<double>(el.center.x), static_cast<double>(el.center.y));
  if (!std::isfinite(a) || std::abs(a - initial.radius) > 3.0 || (c - initial.center).norm() > 3.0) return initial;
  return Circle{c, a};
}

/// Ball circle: [M]'s minimum enclosing circle of the ball contour.
std::optional<Circle> ballCircle(const std::vector<cv::Point>& contour) {
  if (contour.empty()) return std::nullopt;
  cv::Point2f center;
  float radius = 0.0F;
  cv::minEnclosingCircle(contour, center, radius);
  return Circle{{static_cast<double>(center.x), static_cast<double>(center.y)}, static_cast<double>(radius)};
}

/// The cheap part shared by the reference and the production pipeline: from the table contour
/// and the ball contour to the measurements.
TableScene finishScene(const cv::Mat& bgr, const std::vector<cv::Point>* table_contour, double table_area,
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
    scene.ball_circle = ballCircle(*ball_contour);
    if (refine && !ball_clipped && scene.ball_circle) {
      // Sphere cone from [M]'s circle (off by up to about 1 px); the greenness ellipse when the
      // cone is refused (partial outline: ball against the black border or occluded).
      std::optional<Circle> cone;
      if (cfg.ball_outline == TableDetectorConfig::BallOutline::SphereCone)
        cone = refineBallBySphereCone(bgr, camera, *scene.ball_circle, cfg.ball_outline_params, 1.0);
      scene.ball_circle = cone ? *cone : refineBallCircle(bgr, *scene.ball_circle);
    }
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
      std::array<std::vector<Eigen::Vector2d>, 4> edges;
      if (refine) ordered = refineCorners(bgr, ordered, scene.ball_circle, cfg, &edges);
      auto pose = solveTablePose(ordered, camera, cfg.side_m, refine, prior);
      if (pose && refine && cfg.border_height_m > 0.0)
        pose.value().c_M_t = refinePoseWithBorders(pose->c_M_t, ordered, pose->corners, edges, camera, cfg.side_m,
                                                   cfg.border_height_m);
      if (!pose) {
        scene.table = pose.failure();
      } else if (pose->reprojection_rms_px > cfg.max_reprojection_px) {
        // AP3P fits three corners exactly; a fourth far off means the four points are not the
        // image of the square (a corner hidden by the ball, a cut, clutter): no pose.
        scene.table = Result<TableMeasurement>::fail(
            FailureReason::PoseFailed, "corners are not the image of the square (reprojection RMS " +
                                           std::to_string(pose->reprojection_rms_px) + " px)");
      } else if (pose) {
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
  core::requirePositive(corner_sigma_px, "TableDetectorConfig.corner_sigma_px");
  core::requirePositive(max_reprojection_px, "TableDetectorConfig.max_reprojection_px");
  if (!(border_height_m >= 0.0 && border_height_m < side_m))
    throw core::InvalidInput("TableDetectorConfig.border_height_m must be in [0, side_m)");
  core::requirePositive(ball_edge_noise_px, "TableDetectorConfig.ball_edge_noise_px");
  ball_outline_params.validate();
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
  TableScene scene = finishScene(bgr, table_contour, table_area, ball_contour, ball_area, bgr.size(), stamp,
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
  return finishScene(bgr, t >= 0 ? &contours[static_cast<std::size_t>(t)] : nullptr, table_area,
                     b >= 0 ? &ball_contours[static_cast<std::size_t>(b)] : nullptr, ball_area, bgr.size(),
                     stamp, camera, config, /*refine=*/false, prior, false);
}

}  // namespace viewline::vision
