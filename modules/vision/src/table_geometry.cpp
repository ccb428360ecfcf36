#include "viewline/vision/table_geometry.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "viewline/core/checks.h"
#include "viewline/core/error.h"
#include "viewline/core/frames.h"

namespace viewline::vision {

namespace {

Eigen::Vector2d toEigen(const cv::Point& p) { return {p.x, p.y}; }

}  // namespace

/// Gauss-Newton on the pixel reprojection error of the four corners (what
/// cv::solvePnPRefineLM minimises, without its per-iteration projectPoints/Jacobian matrices):
/// pose perturbed as R ← exp([δω]×) R, t ← t + δt; for X = R P + t,
///   ∂u/∂X = [px/Z, 0, -px X/Z²; 0, py/Z, -py Y/Z²],  ∂X/∂δω = -[R P]×,  ∂X/∂δt = I.
/// A step that does not lower the cost ends the iteration (the start is AP3P's exact fit of
/// three corners, close to the minimum).
Eigen::Isometry3d refinePoseOnPoints(const Eigen::Isometry3d& c_M_t, const std::array<Eigen::Vector3d, 4>& P,
                                     const std::array<Eigen::Vector2d, 4>& uv, double px, double py, double u0,
                                     double v0) {
  const auto cost = [&](const Eigen::Isometry3d& M) {
    double sq = 0.0;
    for (std::size_t k = 0; k < 4; ++k) {
      const Eigen::Vector3d X = M * P[k];
      if (!(X.z() > 1e-9)) return std::numeric_limits<double>::infinity();
      sq += Eigen::Vector2d(u0 + px * X.x() / X.z() - uv[k].x(), v0 + py * X.y() / X.z() - uv[k].y()).squaredNorm();
    }
    return sq;
  };
  Eigen::Isometry3d M = c_M_t;
  double c0 = cost(M);
  if (!std::isfinite(c0)) return c_M_t;
  for (int it = 0; it < 20; ++it) {
    Eigen::Matrix<double, 6, 6> JtJ = Eigen::Matrix<double, 6, 6>::Zero();
    Eigen::Matrix<double, 6, 1> Jtr = Eigen::Matrix<double, 6, 1>::Zero();
    for (std::size_t k = 0; k < 4; ++k) {
      const Eigen::Vector3d RP = M.linear() * P[k];
      const Eigen::Vector3d X = RP + M.translation();
      const double iz = 1.0 / X.z();
      Eigen::Matrix<double, 2, 3> dudX;
      dudX << px * iz, 0.0, -px * X.x() * iz * iz, 0.0, py * iz, -py * X.y() * iz * iz;
      Eigen::Matrix3d skew;
      skew << 0.0, -RP.z(), RP.y(), RP.z(), 0.0, -RP.x(), -RP.y(), RP.x(), 0.0;
      Eigen::Matrix<double, 2, 6> J;
      J.leftCols<3>() = -dudX * skew;
      J.rightCols<3>() = dudX;
      const Eigen::Vector2d r(u0 + px * X.x() * iz - uv[k].x(), v0 + py * X.y() * iz - uv[k].y());
      JtJ += J.transpose() * J;
      Jtr += J.transpose() * r;
    }
    const Eigen::Matrix<double, 6, 1> step = JtJ.ldlt().solve(-Jtr);
    if (!step.allFinite()) break;
    Eigen::Isometry3d next = M;
    const double a = step.head<3>().norm();
    if (a > 0.0) next.linear() = Eigen::AngleAxisd(a, step.head<3>() / a).toRotationMatrix() * M.linear();
    next.translation() += step.tail<3>();
    const double c1 = cost(next);
    if (!(c1 <= c0)) break;
    M = next;
    c0 = c1;
    if (step.norm() < 1e-12) break;
  }
  return M;
}

Result<TableCorners> findTableCorners(const std::vector<cv::Point>& contour,
                                      const std::optional<Circle>& ball, int image_width,
                                      const CornerSearchParams& params) {
  if (contour.size() < 4)
    return Result<TableCorners>::fail(FailureReason::TooFewCorners, "table contour has < 4 points");
  std::vector<cv::Point> hull, approx;
  cv::convexHull(contour, hull);
  cv::approxPolyDP(hull, approx, params.approx_epsilon_fraction * image_width, true);

  TableCorners out;
  // Drop hull points close to the ball (it bites into the red contour).
  if (ball) {
    const double keep_out = params.ball_exclusion_factor * ball->radius + 2.0;
    for (const auto& p : approx)
      if ((toEigen(p) - ball->center).norm() >= keep_out) out.polygon.push_back(p);
  } else {
    out.polygon = approx;
  }
  const std::size_t n = out.polygon.size();
  if (n < 4)
    return Result<TableCorners>::fail(FailureReason::TooFewCorners,
                                      "simplified hull has " + std::to_string(n) + " points");
  // Segments between consecutive points; keep the four longest (in contour order).
  std::vector<std::size_t> idx(n);
  std::iota(idx.begin(), idx.end(), 0);
  auto seg_len = [&](std::size_t i) {
    return (toEigen(out.polygon[(i + 1) % n]) - toEigen(out.polygon[i])).norm();
  };
  std::stable_sort(idx.begin(), idx.end(),
                   [&](std::size_t a, std::size_t b) { return seg_len(a) > seg_len(b); });
  idx.resize(4);
  std::sort(idx.begin(), idx.end());
  for (std::size_t k = 0; k < 4; ++k)
    out.sides[k] = {toEigen(out.polygon[idx[k]]), toEigen(out.polygon[(idx[k] + 1) % n])};

  // Pairwise intersections with centred parameters.
  std::vector<Eigen::Vector2d> found;
  for (std::size_t a = 0; a < 4; ++a) {
    for (std::size_t b = a + 1; b < 4; ++b) {
      const Eigen::Vector2d ma = 0.5 * (out.sides[a][0] + out.sides[a][1]);
      const Eigen::Vector2d ha = 0.5 * (out.sides[a][1] - out.sides[a][0]);
      const Eigen::Vector2d mb = 0.5 * (out.sides[b][0] + out.sides[b][1]);
      const Eigen::Vector2d hb = 0.5 * (out.sides[b][1] - out.sides[b][0]);
      // ma + ta ha = mb + tb hb  ->  [ha, -hb] (ta, tb)ᵀ = mb - ma
      Eigen::Matrix2d A;
      A.col(0) = ha;
      A.col(1) = -hb;
      const double det = A.determinant();
      if (std::abs(det) < 1e-9 * ha.squaredNorm() * hb.squaredNorm() + 1e-12) continue;  // parallel
      const Eigen::Vector2d t = A.inverse() * (mb - ma);
      if (std::abs(t(0)) * std::abs(t(1)) < params.max_ta_tb) found.push_back(ma + t(0) * ha);
    }
  }
  if (found.size() < 4)
    return Result<TableCorners>::fail(
        FailureReason::TooFewCorners,
        "only " + std::to_string(found.size()) + " valid corners (table clipped, occluded or edge-on)");
  if (found.size() > 4)
    return Result<TableCorners>::fail(FailureReason::Ambiguous,
                                      std::to_string(found.size()) + " corner candidates");
  for (std::size_t k = 0; k < 4; ++k) out.corners[k] = found[k];
  return out;
}

std::array<Eigen::Vector2d, 4> orderTableCorners(const std::array<Eigen::Vector2d, 4>& corners) {
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const auto& c : corners) mean += 0.25 * c;
  std::array<Eigen::Vector2d, 4> out = corners;
  std::sort(out.begin(), out.end(), [&](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return std::atan2(a.y() - mean.y(), a.x() - mean.x()) > std::atan2(b.y() - mean.y(), b.x() - mean.x());
  });
  std::size_t start = 0;
  for (std::size_t k = 1; k < 4; ++k)
    if (out[k].sum() < out[start].sum()) start = k;
  std::rotate(out.begin(), out.begin() + static_cast<std::ptrdiff_t>(start), out.end());
  return out;
}

Eigen::Isometry3d turnTableFrame(const Eigen::Isometry3d& c_M_t, int quarter_turns) {
  const int k = ((quarter_turns % 4) + 4) % 4;
  Eigen::Isometry3d t_M_t2 = Eigen::Isometry3d::Identity();
  t_M_t2.linear() = core::rotation(Eigen::Vector3d::UnitZ(), k * 0.5 * core::kPi);
  return c_M_t * t_M_t2;
}

int yawQuarterTurnsTo(const Eigen::Isometry3d& c_M_t, const Eigen::Isometry3d& reference) {
  int best = 0;
  double best_angle = 1e9;
  for (int k = 0; k < 4; ++k) {
    const double a = core::rotationAngle(turnTableFrame(c_M_t, k).linear(), reference.linear());
    if (a < best_angle) {
      best_angle = a;
      best = k;
    }
  }
  return best;
}

Result<TablePose> solveTablePose(const std::array<Eigen::Vector2d, 4>& ordered_corners,
                                 const core::Camera& camera, double side_m, bool refine,
                                 const std::optional<Eigen::Isometry3d>& prior) {
  core::requirePositive(side_m, "solveTablePose: side_m");
  const double h = 0.5 * side_m;
  const std::vector<cv::Point3d> object{{-h, -h, 0.0}, {h, -h, 0.0}, {h, h, 0.0}, {-h, h, 0.0}};
  // Undistort with the camera's own (ViSP) model, then use ideal pixels with K and no distortion.
  const double px = camera.intrinsics.get_px(), py = camera.intrinsics.get_py();
  const double u0 = camera.intrinsics.get_u0(), v0 = camera.intrinsics.get_v0();
  std::vector<cv::Point2d> image;
  for (const auto& c : ordered_corners) {
    core::requireFinite(c, "solveTablePose: corner");
    const Eigen::Vector2d xy = camera.pixelToNormalized(c);
    image.emplace_back(u0 + px * xy.x(), v0 + py * xy.y());
  }
  const cv::Matx33d K(px, 0.0, u0, 0.0, py, v0, 0.0, 0.0, 1.0);
  cv::Mat rvec, tvec;
  bool ok = false;
  try {
    ok = cv::solvePnP(object, image, K, cv::noArray(), rvec, tvec, false, cv::SOLVEPNP_AP3P);
  } catch (const cv::Exception& e) {
    return Result<TablePose>::fail(FailureReason::PoseFailed, std::string("solvePnP: ") + e.what());
  }
  if (!ok) return Result<TablePose>::fail(FailureReason::PoseFailed, "solvePnP(AP3P) found no pose");
  cv::Matx33d Rcv;
  cv::Rodrigues(rvec, Rcv);
  TablePose out;
  Eigen::Matrix3d R;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) R(r, c) = Rcv(r, c);
  out.c_M_t.linear() = R;
  out.c_M_t.translation() = Eigen::Vector3d(tvec.at<double>(0), tvec.at<double>(1), tvec.at<double>(2));
  std::array<Eigen::Vector3d, 4> P;
  std::array<Eigen::Vector2d, 4> uv;
  for (std::size_t k = 0; k < 4; ++k) {
    P[k] = Eigen::Vector3d(object[k].x, object[k].y, 0.0);
    uv[k] = Eigen::Vector2d(image[k].x, image[k].y);
  }
  if (refine) out.c_M_t = refinePoseOnPoints(out.c_M_t, P, uv, px, py, u0, v0);
  if (!out.c_M_t.matrix().allFinite())
    return Result<TablePose>::fail(FailureReason::PoseFailed, "non-finite pose");
  if (out.c_M_t.translation().z() <= 0.0)
    return Result<TablePose>::fail(FailureReason::PoseFailed, "table behind the camera");
  const Eigen::Vector3d cam_in_table = -out.c_M_t.linear().transpose() * out.c_M_t.translation();
  if (cam_in_table.z() <= 0.0)
    return Result<TablePose>::fail(FailureReason::PoseFailed,
                                   "pose shows the table from below (corner order mismatch)");
  double sq = 0.0;
  for (std::size_t k = 0; k < 4; ++k) {
    const Eigen::Vector3d X = out.c_M_t * P[k];
    const Eigen::Vector2d reproj(u0 + px * X.x() / X.z(), v0 + py * X.y() / X.z());
    sq += (reproj - uv[k]).squaredNorm();
  }
  out.reprojection_rms_px = std::sqrt(sq / 4.0);
  out.corners = ordered_corners;
  if (prior) {
    const int k = yawQuarterTurnsTo(out.c_M_t, *prior);
    out.c_M_t = turnTableFrame(out.c_M_t, k);
    // Frame turned by k quarter turns: object corner P_i is now the old P_{i+k}.
    std::array<Eigen::Vector2d, 4> turned;
    for (std::size_t i = 0; i < 4; ++i) turned[i] = ordered_corners[(i + static_cast<std::size_t>(k)) % 4];
    out.corners = turned;
  }
  return out;
}

BallOnTableGeometry ballViewingCone(const core::Camera& camera, const Circle& circle) {
  core::requireFinite(circle.center, "ballViewingCone: circle centre");
  core::requirePositive(circle.radius, "ballViewingCone: circle radius");
  const Eigen::Vector2d p0(camera.intrinsics.get_u0(), camera.intrinsics.get_v0());
  Eigen::Vector2d e = circle.center - p0;
  e = e.norm() > 1e-9 ? Eigen::Vector2d(e.normalized()) : Eigen::Vector2d(1.0, 0.0);
  const Eigen::Vector2d a = circle.center + circle.radius * e;
  const Eigen::Vector2d b = circle.center - circle.radius * e;
  const Eigen::Vector2d xa = camera.pixelToNormalized(a), xb = camera.pixelToNormalized(b);
  BallOnTableGeometry g;
  g.va = Eigen::Vector3d(xa.x(), xa.y(), 1.0).normalized();
  g.vb = Eigen::Vector3d(xb.x(), xb.y(), 1.0).normalized();
  g.alpha = 0.5 * std::acos(std::clamp(g.va.dot(g.vb), -1.0, 1.0));
  g.ray_c = (g.va + g.vb).normalized();
  return g;
}

BallOnTableGeometry ballOnTableKnownRadius(const core::Camera& camera, const Circle& circle,
                                           const Eigen::Isometry3d& c_M_t, double r_m) {
  core::requirePositive(r_m, "ballOnTableKnownRadius: r_m");
  BallOnTableGeometry g = ballViewingCone(camera, circle);
  g.radius_m = r_m;
  g.distance_m = r_m / std::sin(g.alpha);  // d = r / sin α (erratum of [M] eq 4.12)
  const Eigen::Matrix3d R = c_M_t.linear();
  const Eigen::Vector3d t_prime = -R.transpose() * c_M_t.translation();
  const Eigen::Vector3d v1 = R.transpose() * g.ray_c;
  g.p_t = t_prime + g.distance_m * v1;
  g.p_c = g.distance_m * g.ray_c;
  return g;
}

std::optional<BallOnTableGeometry> ballOnTableUnknownRadius(const core::Camera& camera,
                                                            const Circle& circle,
                                                            const Eigen::Isometry3d& c_M_t) {
  BallOnTableGeometry g = ballViewingCone(camera, circle);
  const Eigen::Matrix3d R = c_M_t.linear();
  const Eigen::Vector3d t_prime = -R.transpose() * c_M_t.translation();
  const Eigen::Vector3d v1 = R.transpose() * g.ray_c;
  const double sin_a = std::sin(g.alpha);
  const double sigma = t_prime.z() >= 0.0 ? 1.0 : -1.0;
  const double denom = sigma - v1.z() / sin_a;  // r = t'_z / (σ - v1_z / sin α)
  if (!(std::abs(denom) > 1e-9)) return std::nullopt;
  const double r = t_prime.z() / denom;
  if (!(r > 0.0) || !std::isfinite(r)) return std::nullopt;
  g.radius_m = r;
  g.distance_m = r / sin_a;
  g.p_t = t_prime + g.distance_m * v1;
  g.p_c = g.distance_m * g.ray_c;
  return g;
}

}  // namespace viewline::vision
