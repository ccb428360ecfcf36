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

namespace {

// One pass over an 8-bit image: per-channel gain (Q8 fixed point, repeated along a row so the
// loops vectorise) and/or additive noise values, saturated to [0, 255].
void gainAndNoise(cv::Mat& img, const Eigen::Vector3d* gain, const std::int8_t* noise) {
  const int ch = img.channels();
  const auto row_len = static_cast<std::size_t>(img.cols) * static_cast<std::size_t>(ch);
  std::vector<std::uint16_t> g(gain != nullptr ? row_len : 0);
  for (std::size_t i = 0; i < g.size(); ++i) {
    const double gi = (*gain)[static_cast<Eigen::Index>(i % static_cast<std::size_t>(ch) % 3)];
    g[i] = static_cast<std::uint16_t>(std::clamp(std::lround(256.0 * gi), 0L, 65535L));
  }
  for (int j = 0; j < img.rows; ++j) {
    uchar* p = img.ptr<uchar>(j);
    const std::int8_t* q = noise != nullptr ? noise + static_cast<std::size_t>(j) * row_len : nullptr;
    if (gain != nullptr && q != nullptr) {
      const std::uint16_t* gr = g.data();
      for (std::size_t i = 0; i < row_len; ++i) {
        const int v = static_cast<int>((static_cast<std::uint32_t>(p[i]) * gr[i] + 128u) >> 8) + q[i];
        p[i] = static_cast<uchar>(v < 0 ? 0 : (v > 255 ? 255 : v));
      }
    } else if (gain != nullptr) {
      const std::uint16_t* gr = g.data();
      for (std::size_t i = 0; i < row_len; ++i) {
        const std::uint32_t v = (static_cast<std::uint32_t>(p[i]) * gr[i] + 128u) >> 8;
        p[i] = static_cast<uchar>(v > 255u ? 255u : v);
      }
    } else if (q != nullptr) {
      for (std::size_t i = 0; i < row_len; ++i) {
        const int v = p[i] + q[i];
        p[i] = static_cast<uchar>(v < 0 ? 0 : (v > 255 ? 255 : v));
      }
    }
  }
}

bool unitGain(const Eigen::Vector3d& g) { return (g.array() - 1.0).abs().maxCoeff() < 1e-12; }

}  // namespace

void applyIllumination(cv::Mat& bgr8, const Illumination& il, double t) {
  if (bgr8.type() != CV_8UC3) throw InvalidInput("applyIllumination: image must be CV_8UC3");
  const Eigen::Vector3d g = illuminationGain(il, t);
  if (!unitGain(g)) gainAndNoise(bgr8, &g, nullptr);
}

NoisePool::NoisePool(const SensorNoise& noise, core::Rng& rng) : sigma_(noise.sigma) {
  requireRange(noise.sigma, 0.0, 255.0, false, "SensorNoise.sigma");
  if (noise.pool_size < 1024) throw InvalidInput("SensorNoise.pool_size must be >= 1024");
  if (sigma_ <= 0.0 || sigma_ > kMaxPoolSigma) return;  // large sigma: cv::randn path
  // OpenCV's Ziggurat sampler (local engine seeded from rng): millions of draws in milliseconds.
  cv::Mat draws(1, static_cast<int>(noise.pool_size), CV_32F);
  cv::RNG local(rng());
  local.fill(draws, cv::RNG::NORMAL, 0.0, sigma_);
  pool_.resize(noise.pool_size);
  const float* d = draws.ptr<float>(0);
  for (std::size_t i = 0; i < pool_.size(); ++i) {
    pool_[i] = static_cast<std::int8_t>(std::clamp(std::lround(static_cast<double>(d[i])), -127L, 127L));
  }
}

void NoisePool::apply(cv::Mat& image, core::Rng& rng) const { applyWithGain(image, Eigen::Vector3d::Ones(), rng); }

void NoisePool::applyWithGain(cv::Mat& image, const Eigen::Vector3d& gain, core::Rng& rng) const {
  if (image.depth() != CV_8U) throw InvalidInput("NoisePool::apply: image must be 8-bit");
  const bool with_gain = !unitGain(gain);
  if (sigma_ <= 0.0) {
    if (with_gain) gainAndNoise(image, &gain, nullptr);
    return;
  }
  const std::size_t n = image.total() * static_cast<std::size_t>(image.channels());
  if (!image.isContinuous() || n > pool_.size()) {
    if (with_gain) gainAndNoise(image, &gain, nullptr);
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
  gainAndNoise(image, with_gain ? &gain : nullptr, pool_.data() + off(rng));
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
