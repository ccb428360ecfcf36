#include "viewline/vision/ball_outline.h"

#include <algorithm>
#include <cmath>
#include <Eigen/Dense>

#include "viewline/core/checks.h"
#include "viewline/core/error.h"
#include "viewline/core/frames.h"

namespace viewline::vision {

namespace {

/// Bilinear BGR sample (8-bit units) at (u, v) in [0, cols - 1) x [0, rows - 1) (not checked).
inline void colourAt(const cv::Mat& bgr, double u, double v, Eigen::Vector3d& out) {
  const int x = static_cast<int>(u), y = static_cast<int>(v);
  const double fx = u - x, fy = v - y;
  const unsigned char* r0 = bgr.ptr<unsigned char>(y) + 3 * x;
  const unsigned char* r1 = bgr.ptr<unsigned char>(y + 1) + 3 * x;
  const double w00 = (1 - fx) * (1 - fy), w01 = fx * (1 - fy), w10 = (1 - fx) * fy, w11 = fx * fy;
  for (int k = 0; k < 3; ++k) out(k) = w00 * r0[k] + w01 * r0[k + 3] + w10 * r1[k] + w11 * r1[k + 3];
}

struct BallColour {
  Eigen::Vector3d dir;  ///< B, unit
  double level = 0.0;   ///< mean P·B of the interior pixels
};

/// B: normalised sum of the colours of the pixels within 0.6 ρ of the centre, then once more
/// without the pixels more than 6° away from the first direction (a highlight, an occluder).
std::optional<BallColour> ballChromaticity(const cv::Mat& bgr, const Circle& c) {
  const double rin = 0.6 * c.radius;
  const int x0 = std::max(0, static_cast<int>(std::floor(c.center.x() - rin)));
  const int x1 = std::min(bgr.cols - 1, static_cast<int>(std::ceil(c.center.x() + rin)));
  const int y0 = std::max(0, static_cast<int>(std::floor(c.center.y() - rin)));
  const int y1 = std::min(bgr.rows - 1, static_cast<int>(std::ceil(c.center.y() + rin)));
  Eigen::Vector3d dir = Eigen::Vector3d::Zero();
  double level = 0.0;
  for (int pass = 0; pass < 2; ++pass) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    int n = 0;
    const double cos_gate = std::cos(core::deg2rad(6.0));
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) {
        if ((Eigen::Vector2d(x, y) - c.center).squaredNorm() > rin * rin) continue;
        const cv::Vec3b& p = bgr.at<cv::Vec3b>(y, x);
        const Eigen::Vector3d P(p[0], p[1], p[2]);
        if (pass == 1 && P.dot(dir) < cos_gate * P.norm()) continue;
        sum += P;
        ++n;
      }
    if (n < 5 || sum.norm() < 1e-9) return std::nullopt;
    dir = sum.normalized();
    level = sum.norm() / n;
  }
  return BallColour{dir, level};
}

}  // namespace

void BallOutlineParams::validate() const {
  if (rays < 8 || rays > 1024) throw core::InvalidInput("BallOutlineParams.rays must be in [8, 1024]");
  core::requirePositive(reach_px, "BallOutlineParams.reach_px");
  core::requirePositive(min_separation, "BallOutlineParams.min_separation");
  core::requirePositive(max_coverage_error, "BallOutlineParams.max_coverage_error");
  core::requirePositive(clean_margin_px, "BallOutlineParams.clean_margin_px");
  if (!(min_ball_level > 0.0 && min_ball_level < 1.0)) throw core::InvalidInput("BallOutlineParams.min_ball_level must be in (0, 1)");
  if (clean_margin_px >= reach_px) throw core::InvalidInput("BallOutlineParams.clean_margin_px must be < reach_px");
  if (min_points < 5) throw core::InvalidInput("BallOutlineParams.min_points must be >= 5");
  core::requirePositive(outlier_floor_px, "BallOutlineParams.outlier_floor_px");
  core::requirePositive(max_alpha_sigma_px, "BallOutlineParams.max_alpha_sigma_px");
  if (!(max_gap_deg > 0.0 && max_gap_deg <= 360.0)) throw core::InvalidInput("BallOutlineParams.max_gap_deg must be in (0, 360]");
}

namespace {

std::vector<Eigen::Vector2d> outlinePoints(const cv::Mat& bgr, const Circle& initial, const BallOutlineParams& params,
                                           const std::optional<BallColour>& ball) {
  std::vector<Eigen::Vector2d> out;
  if (bgr.type() != CV_8UC3 || !(initial.radius > 2.0) || !initial.center.allFinite() || !ball) return out;
  const Eigen::Vector3d& B = ball->dir;
  constexpr double kStep = 0.25;
  const double reach = std::clamp(params.reach_px, 1.5, std::max(1.5, 0.45 * initial.radius));
  const double r0 = initial.radius - reach, r1 = initial.radius + reach;
  const int count = static_cast<int>(std::lround((r1 - r0) / kStep)) + 1;
  const int tail = static_cast<int>(std::lround(1.0 / kStep));  // last pixel of the ray: background
  // The whole ray must lie in the image (bilinear samples read the next pixel too).
  const double lim_u = bgr.cols - 1.001, lim_v = bgr.rows - 1.001;
  std::vector<Eigen::Vector3d> prof(static_cast<std::size_t>(count));
  std::vector<double> cov(static_cast<std::size_t>(count));
  std::vector<char> mix_ok(static_cast<std::size_t>(count));
  out.reserve(static_cast<std::size_t>(params.rays));
  for (int i = 0; i < params.rays; ++i) {
    const double th = 2.0 * core::kPi * (i + 0.5) / params.rays;
    const Eigen::Vector2d n(std::cos(th), std::sin(th));
    const Eigen::Vector2d pa = initial.center + r0 * n, pb = initial.center + r1 * n;
    if (!(std::min(pa.x(), pb.x()) >= 0.0 && std::min(pa.y(), pb.y()) >= 0.0 && std::max(pa.x(), pb.x()) <= lim_u &&
          std::max(pa.y(), pb.y()) <= lim_v))
      continue;
    const auto sample = [&](int k) {
      const Eigen::Vector2d p = initial.center + (r0 + k * kStep) * n;
      colourAt(bgr, p.x(), p.y(), prof[static_cast<std::size_t>(k)]);
    };
    // Background first (the last pixel of the ray): rays against a colour too close to the
    // ball's (black border, shadow) are dropped before sampling the rest.
    Eigen::Vector3d T = Eigen::Vector3d::Zero();
    for (int k = count - tail; k < count; ++k) {
      sample(k);
      T += prof[static_cast<std::size_t>(k)];
    }
    T /= tail;
    const Eigen::Vector3d Tp = T - T.dot(B) * B;  // T⊥
    const double sep2 = Tp.squaredNorm();
    if (sep2 < params.min_separation * params.min_separation) continue;
    for (int k = 0; k < count - tail; ++k) sample(k);
    // c(s) = 1 - P·T⊥ / |T⊥|². The two-colour model P = a B + (1 - c) T holds when P has no
    // component along m = B × T⊥ (the normal of the plane of B and T); then a = P·B - (1 - c) T·B.
    const Eigen::Vector3d m = B.cross(Tp) / std::sqrt(sep2);
    const double tol = params.max_coverage_error * std::sqrt(sep2), TB = T.dot(B);
    const double min_level = params.min_ball_level * ball->level;
    for (int k = 0; k < count; ++k) {
      const Eigen::Vector3d& P = prof[static_cast<std::size_t>(k)];
      const double c = 1.0 - P.dot(Tp) / sep2;
      cov[static_cast<std::size_t>(k)] = c;
      mix_ok[static_cast<std::size_t>(k)] =
          std::abs(P.dot(m)) <= tol && (c < 0.3 || P.dot(B) - (1.0 - c) * TB >= min_level * c) ? 1 : 0;
    }
    // R² = r0² + 2 ∫ c s ds (trapezoid).
    double integral = 0.0;
    for (int k = 1; k < count; ++k) {
      const double s = r0 + k * kStep;
      integral += 0.5 * kStep * (cov[static_cast<std::size_t>(k - 1)] * (s - kStep) + cov[static_cast<std::size_t>(k)] * s);
    }
    const double R2 = r0 * r0 + 2.0 * integral;
    if (!(R2 > 0.0)) continue;
    const double R = std::sqrt(R2);
    if (R <= r0 || R >= r1) continue;
    // One clean step only: every sample a two-colour mix (within tol) and, where it holds some
    // ball (c ≥ 0.3), a ball brightness a / c of at least min_ball_level of the interior's (black
    // is s·B with s = 0: a black strip would otherwise pass for ball); c = 1 up to the margin
    // inside the edge and c = 0 from the margin outside (within max_coverage_error).
    bool clean = true;
    for (int k = 0; k < count && clean; ++k) {
      const double s = r0 + k * kStep, c = cov[static_cast<std::size_t>(k)];
      clean = mix_ok[static_cast<std::size_t>(k)] != 0;
      if (s <= R - params.clean_margin_px) clean = clean && std::abs(c - 1.0) <= params.max_coverage_error;
      if (s >= R + params.clean_margin_px) clean = clean && std::abs(c) <= params.max_coverage_error;
    }
    if (!clean) continue;
    out.push_back(initial.center + R * n);
  }
  return out;
}

}  // namespace

std::vector<Eigen::Vector2d> ballOutlinePoints(const cv::Mat& bgr, const Circle& initial,
                                               const BallOutlineParams& params) {
  if (bgr.type() != CV_8UC3 || !(initial.radius > 2.0) || !initial.center.allFinite()) return {};
  return outlinePoints(bgr, initial, params, ballChromaticity(bgr, initial));
}

std::optional<SphereCone> fitSphereCone(const core::Camera& camera, const std::vector<Eigen::Vector2d>& outline_px,
                                        const BallOutlineParams& params) {
  if (static_cast<int>(outline_px.size()) < params.min_points) return std::nullopt;
  const double f = camera.intrinsics.get_px();
  std::vector<Eigen::Vector3d> w;
  w.reserve(outline_px.size());
  for (const auto& uv : outline_px) {
    const Eigen::Vector2d xy = camera.pixelToNormalized(uv);
    w.push_back(Eigen::Vector3d(xy.x(), xy.y(), 1.0).normalized());
  }
  std::vector<char> use(w.size(), 1);
  SphereCone cone;
  std::vector<double> res(w.size()), absdev;
  for (int round = 0; round < 2; ++round) {
    Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
    Eigen::Vector3d b = Eigen::Vector3d::Zero();
    int n = 0;
    for (std::size_t i = 0; i < w.size(); ++i) {
      if (!use[i]) continue;
      A += w[i] * w[i].transpose();
      b += w[i];
      ++n;
    }
    if (n < params.min_points) return std::nullopt;
    const Eigen::Vector3d u = A.ldlt().solve(b);  // argmin Σ (wᵢ·u - 1)²
    const double un = u.norm();
    if (!u.allFinite() || !(un > 1.0)) return std::nullopt;
    cone.axis = u / un;
    cone.alpha = std::acos(1.0 / un);
    double sq = 0.0;
    absdev.clear();
    for (std::size_t i = 0; i < w.size(); ++i) {
      res[i] = std::acos(std::clamp(w[i].dot(cone.axis), -1.0, 1.0)) - cone.alpha;
      if (use[i]) {
        sq += res[i] * res[i];
        absdev.push_back(std::abs(res[i]));
      }
    }
    cone.inliers = n;
    cone.rms_px = f * std::sqrt(sq / n);
    // σ_α from the linear fit: cov(u) = σ² A⁻¹ with σ the residual of wᵢ·u - 1 (≈ tan α times
    // the angular residual), and dα = (v·du) / (|u|² sin α).
    {
      const double sigma2 = std::pow(std::tan(cone.alpha), 2) * sq / std::max(1, n - 3);
      const double var_u = sigma2 * cone.axis.dot(A.ldlt().solve(cone.axis));
      cone.alpha_sigma_px = f * std::sqrt(std::max(0.0, var_u)) / (un * un * std::sin(cone.alpha));
    }
    // Largest gap between the inliers around the axis.
    const Eigen::Vector3d e1 = cone.axis.unitOrthogonal(), e2 = cone.axis.cross(e1);
    std::vector<double> az;
    for (std::size_t i = 0; i < w.size(); ++i)
      if (use[i]) az.push_back(std::atan2(w[i].dot(e2), w[i].dot(e1)));
    std::sort(az.begin(), az.end());
    cone.max_gap_rad = 2.0 * core::kPi - (az.back() - az.front());
    for (std::size_t i = 1; i < az.size(); ++i) cone.max_gap_rad = std::max(cone.max_gap_rad, az[i] - az[i - 1]);
    if (round == 1) break;
    std::nth_element(absdev.begin(), absdev.begin() + static_cast<std::ptrdiff_t>(absdev.size() / 2), absdev.end());
    const double mad = absdev[absdev.size() / 2];
    const double gate = std::max(3.0 * 1.4826 * mad, params.outlier_floor_px / f);
    bool changed = false;
    for (std::size_t i = 0; i < w.size(); ++i) {
      const char keep = std::abs(res[i]) <= gate ? 1 : 0;
      changed = changed || keep != use[i];
      use[i] = keep;
    }
    if (!changed) break;
  }
  return cone;
}

Circle circleFromSphereCone(const core::Camera& camera, const SphereCone& cone) {
  const Eigen::Vector3d v = cone.axis.normalized();
  // Unit vector perpendicular to v in the plane of v and the optical axis (any when v = z).
  Eigen::Vector3d e = Eigen::Vector3d::UnitZ() - v.z() * v;
  e = e.norm() > 1e-12 ? Eigen::Vector3d(e.normalized()) : Eigen::Vector3d::UnitX();
  const Eigen::Vector3d ra = std::cos(cone.alpha) * v + std::sin(cone.alpha) * e;
  const Eigen::Vector3d rb = std::cos(cone.alpha) * v - std::sin(cone.alpha) * e;
  const Eigen::Vector2d a = camera.normalizedToPixel(ra.head<2>() / ra.z());
  const Eigen::Vector2d b = camera.normalizedToPixel(rb.head<2>() / rb.z());
  return Circle{0.5 * (a + b), 0.5 * (a - b).norm()};
}

std::optional<Circle> refineBallBySphereCone(const cv::Mat& bgr, const core::Camera& camera, const Circle& initial,
                                             const BallOutlineParams& params, double initial_error_px) {
  // Pass 1: half the rays, reach widened by the initial circle's error, no coverage gates
  // (only a circle to centre pass 2 on). Pass 2: params as given, gated.
  BallOutlineParams coarse = params;
  coarse.rays = std::max(8, params.rays / 2);
  coarse.min_points = std::max(5, params.min_points / 2);
  coarse.reach_px = params.reach_px + std::max(0.0, initial_error_px);
  if (bgr.type() != CV_8UC3 || !(initial.radius > 2.0) || !initial.center.allFinite()) return std::nullopt;
  const auto colour = ballChromaticity(bgr, initial);  // B and its level, once
  Circle c = initial;
  for (int pass = 0; pass < 2; ++pass) {
    const BallOutlineParams& p = pass == 0 ? coarse : params;
    const auto cone = fitSphereCone(camera, outlinePoints(bgr, c, p, colour), p);
    if (!cone) return std::nullopt;
    if (pass == 1 && (cone->max_gap_rad > core::deg2rad(params.max_gap_deg) || cone->alpha_sigma_px > params.max_alpha_sigma_px))
      return std::nullopt;
    const Circle next = circleFromSphereCone(camera, *cone);
    if (!next.center.allFinite() || !std::isfinite(next.radius) ||
        (next.center - initial.center).norm() > 3.0 + initial_error_px ||
        std::abs(next.radius - initial.radius) > 3.0 + initial_error_px)
      return std::nullopt;
    c = next;
  }
  return c;
}

}  // namespace viewline::vision
