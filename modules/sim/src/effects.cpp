#include "viewline/sim/effects.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "viewline/core/checks.h"
#include "viewline/core/frames.h"

namespace viewline::sim {

using core::InvalidInput;

namespace {
void requireRange(double v, double lo, double hi, bool hi_open, const std::string& what) {
  core::requireFinite(v, what);
  if (v < lo || v > hi || (hi_open && v >= hi)) {
    std::ostringstream s;
    s << what << " = " << v << " (expected in [" << lo << ", " << hi << (hi_open ? "))" : "])");
    throw InvalidInput(s.str());
  }
}
}  // namespace

void validate(const ImagingEffects& e) {
  requireRange(e.noise.sigma, 0.0, 255.0, false, "effects.noise.sigma");
  if (e.noise.pool_size < 1024) throw InvalidInput("effects.noise.pool_size must be >= 1024");
  requireRange(e.blur.exposure, 0.0, 10.0, false, "effects.blur.exposure");
  if (e.blur.samples < 1) throw InvalidInput("effects.blur.samples must be >= 1");
  core::requirePositive(e.illumination.gain, "effects.illumination.gain");
  for (int c = 0; c < 3; ++c) core::requirePositive(e.illumination.white_balance_bgr[c], "effects.illumination.white_balance_bgr");
  requireRange(e.illumination.flicker_amplitude, 0.0, 1.0, true, "effects.illumination.flicker_amplitude");
  requireRange(e.illumination.flicker_frequency, 0.0, 1e6, false, "effects.illumination.flicker_frequency");
  core::requireFinite(e.illumination.drift, "effects.illumination.drift");
  requireRange(e.occlusion.fraction, 0.0, 1.0, false, "effects.occlusion.fraction");
  core::requireFinite(e.occlusion.direction, "effects.occlusion.direction");
  requireRange(e.occlusion.depth_ratio, 1e-3, 1.0, true, "effects.occlusion.depth_ratio");
  requireRange(e.faults.drop_probability, 0.0, 1.0, true, "effects.faults.drop_probability");
  requireRange(e.faults.stamp_jitter, 0.0, 1.0, false, "effects.faults.stamp_jitter");
  requireRange(e.faults.trigger_jitter, 0.0, 1.0, false, "effects.faults.trigger_jitter");
}

Eigen::Vector3d illuminationGain(const Illumination& il, double t) {
  const double g = il.gain * (1.0 + il.flicker_amplitude * std::sin(2.0 * core::kPi * il.flicker_frequency * t)) *
                   std::max(0.0, 1.0 + il.drift * t);
  return g * il.white_balance_bgr;
}

void applyIllumination(cv::Mat& bgr8, const Illumination& il, double t) {
  if (bgr8.type() != CV_8UC3) throw InvalidInput("applyIllumination: image must be CV_8UC3");
  const Eigen::Vector3d g = illuminationGain(il, t);
  if ((g.array() - 1.0).abs().maxCoeff() < 1e-12) return;
  cv::Mat lut(1, 256, CV_8UC3);
  for (int i = 0; i < 256; ++i) {
    for (int c = 0; c < 3; ++c) lut.at<cv::Vec3b>(0, i)[c] = cv::saturate_cast<uchar>(g[c] * i);
  }
  cv::LUT(bgr8, lut, bgr8);
}

NoisePool::NoisePool(const SensorNoise& noise, core::Rng& rng) : sigma_(noise.sigma) {
  requireRange(noise.sigma, 0.0, 255.0, false, "SensorNoise.sigma");
  if (sigma_ <= 0.0) return;
  pool_.resize(noise.pool_size);
  std::normal_distribution<double> n(0.0, sigma_);
  for (auto& v : pool_) v = static_cast<std::int16_t>(std::clamp(std::lround(n(rng)), -255L, 255L));
}

void NoisePool::apply(cv::Mat& image, core::Rng& rng) const {
  if (sigma_ <= 0.0) return;
  if (image.depth() != CV_8U) throw InvalidInput("NoisePool::apply: image must be 8-bit");
  const std::size_t n = image.total() * static_cast<std::size_t>(image.channels());
  if (!image.isContinuous() || n > pool_.size()) {
    cv::Mat noise(image.size(), CV_MAKETYPE(CV_16S, image.channels()));
    cv::RNG local(rng());
    local.fill(noise, cv::RNG::NORMAL, 0.0, sigma_);
    cv::Mat wide;
    image.convertTo(wide, CV_16S);
    wide += noise;
    wide.convertTo(image, image.type());
    return;
  }
  std::uniform_int_distribution<std::size_t> off(0, pool_.size() - n);
  const std::int16_t* q = pool_.data() + off(rng);
  uchar* p = image.data;
  for (std::size_t i = 0; i < n; ++i) {
    const int v = p[i] + q[i];
    p[i] = static_cast<uchar>(v < 0 ? 0 : (v > 255 ? 255 : v));
  }
}

double discSegmentFraction(double d) {
  const double c = std::clamp(d, -1.0, 1.0);
  return (std::acos(c) - c * std::sqrt(1.0 - c * c)) / core::kPi;
}

std::optional<Primitive> makeOccluder(const ObjectTruth& target, const core::Camera& camera,
                                      const Occlusion& occ, double direction) {
  if (occ.fraction <= 0.0 || !target.in_front) return std::nullopt;
  const Eigen::Vector3d P = target.c_M_o.translation();
  // Apparent radius in normalised units (from the silhouette when known).
  double rho = 0.0;
  if (target.enclosing_radius_px > 0.0) {
    rho = target.enclosing_radius_px / camera.focalPx();
  } else {
    rho = 0.05 * P.norm() / P.z();
  }
  // Chord distance d (units of rho) whose far side holds `fraction` of the disc (bisection).
  double lo = -1.0, hi = 1.0;
  for (int i = 0; i < 60; ++i) {
    const double mid = 0.5 * (lo + hi);
    if (discSegmentFraction(mid) > occ.fraction) lo = mid;
    else hi = mid;
  }
  double d = 0.5 * (lo + hi);
  if (occ.fraction >= 1.0) d = -1.5;  // cover everything with a margin
  const Eigen::Vector2d m(P.x() / P.z(), P.y() / P.z());
  const Eigen::Vector2d nrm(std::cos(direction), std::sin(direction));
  const double width = 8.0 * rho;  // along the edge normal, beyond the chord
  const Eigen::Vector2d c = m + (d * rho + 0.5 * width) * nrm;
  const double z = occ.depth_ratio * P.z();
  Eigen::Isometry3d c_M_occ = Eigen::Isometry3d::Identity();
  c_M_occ.linear() = core::rotation(Eigen::Vector3d::UnitZ(), direction);
  c_M_occ.translation() = Eigen::Vector3d(c.x() * z, c.y() * z, z);
  Primitive p;
  p.shape = Shape::Rectangle;
  p.w_M_o = camera.c_M_w.inverse() * c_M_occ;
  p.size = Eigen::Vector3d(width * z, width * z, 0.0);
  p.material.albedo_bgr = occ.colour_bgr;
  return p;
}

}  // namespace viewline::sim
