// The viewline tracker's per-camera pixel bias (TrackerConfig::pixel_bias, tracker.h) on a
// synthetic two-camera rig: a constant bias per camera and track (drawn from N(0, σ_b² I)) plus
// white pixel noise. Every flight is drawn from the tracker's prior and has no process noise, so
// a filter told the true model is consistent: its NEES (6 dof, one per track) and NIS (2 dof, one
// per image) have known chi-square distributions, and their means over the tracks lie in the
// 99 % bands [χ²(n k, 0.005) / k, χ²(n k, 0.995) / k] (k samples, counted as independent).

#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include "viewline/core/error.h"
#include "viewline/core/frames.h"
#include "viewline/core/random.h"
#include "viewline/core/statistics.h"
#include "viewline/tracking/tracker.h"
#include "viewline/tracking/viewline.h"

using namespace viewline;
using namespace viewline::tracking;

namespace {

constexpr double kWhitePx = 0.10;  // white pixel noise per axis
constexpr double kBiasPx = 0.15;   // std of each camera's constant bias per axis

core::Camera makeCamera(const Eigen::Vector3d& eye, const Eigen::Vector3d& target) {
  core::Camera cam;
  cam.width = 656;
  cam.height = 480;
  cam.intrinsics = core::intrinsicsFromFov(core::deg2rad(62.0), 656, 480);
  cam.c_M_w = core::lookAt(eye, target, Eigen::Vector3d::UnitZ());
  return cam;
}

// A throw along +x seen from the side and from beside its end, 4-7 m away.
std::vector<core::Camera> rig() {
  return {makeCamera({2.0, -5.5, 1.8}, {2.0, 0.0, 1.4}), makeCamera({6.5, 3.0, 2.0}, {2.0, 0.0, 1.4})};
}

TrackerConfig baseConfig() {
  TrackerConfig c;
  c.prior_mean << 0.0, 0.0, 1.3, 7.5, 0.0, 2.0;
  c.prior_cov.setZero();
  c.prior_cov.diagonal() << 0.04, 0.04, 0.04, 0.25, 0.25, 0.25;
  c.model.accel_psd = 0.0;  // the flights are exactly ballistic
  return c;
}

// One flight: the state at t = 0 drawn from the prior, each camera at 50 Hz with its own phase,
// 0.5 s; every pixel = the ball's exact image + the camera's bias + white noise.
struct Flight {
  Vector6 x0;
  std::vector<ImageMeasurement> images;
  Vector6 truthAt(double t, const BallisticModel& model) const { return model.propagate(x0, t); }
};

Flight drawFlight(const std::vector<core::Camera>& cams, const TrackerConfig& cfg, const std::vector<double>& bias_px,
                  core::Rng& rng, std::uint64_t& next_id) {
  Flight f;
  f.x0 = core::sampleGaussian(rng, cfg.prior_mean, cfg.prior_cov);
  std::vector<Eigen::Vector2d> bias(cams.size());
  for (std::size_t c = 0; c < cams.size(); ++c)
    bias[c] = {core::gaussian(rng, bias_px[c]), core::gaussian(rng, bias_px[c])};
  for (std::size_t c = 0; c < cams.size(); ++c) {
    const double phase = core::uniform(rng, 0.0, 0.02);
    for (double t = phase; t < 0.5; t += 0.02) {
      const Eigen::Vector3d p = f.truthAt(t, cfg.model).head<3>();
      const Eigen::Vector3d pc = cams[c].c_M_w * p;
      Eigen::Vector2d uv = exactPixelOf(cams[c], {pc.x() / pc.z(), pc.y() / pc.z()});
      uv += bias[c] + Eigen::Vector2d(core::gaussian(rng, kWhitePx), core::gaussian(rng, kWhitePx));
      f.images.push_back({next_id++, c, t, uv, kWhitePx});
    }
  }
  std::sort(f.images.begin(), f.images.end(),
            [](const ImageMeasurement& a, const ImageMeasurement& b) { return a.t < b.t; });
  return f;
}

struct Consistency {
  double nees = 0.0;  // mean over tracks (end of each flight)
  double nis = 0.0;   // mean over images with >= 4 fused images before them
  int tracks = 0, nis_samples = 0;
  bool inNeesBand() const { return nees >= band(6, tracks, 0.005) && nees <= band(6, tracks, 0.995); }
  bool inNisBand() const { return nis >= band(2, nis_samples, 0.005) && nis <= band(2, nis_samples, 0.995); }
  static double band(int dof, int k, double p) { return core::chiSquareQuantile(dof * k, p) / k; }
};

Consistency run(const TrackerConfig& cfg, int tracks, std::uint64_t seed,
                const std::vector<double>& bias_px = {kBiasPx, kBiasPx}) {
  const std::vector<core::Camera> cams = rig();
  core::Rng rng = core::makeRng(seed);
  std::uint64_t id = 1;
  Consistency out;
  double nees_sum = 0.0, nis_sum = 0.0;
  for (int k = 0; k < tracks; ++k) {
    const Flight f = drawFlight(cams, cfg, bias_px, rng, id);
    ViewlineTracker tr(cams, cfg);
    for (const ImageMeasurement& m : f.images) {
      EXPECT_EQ(tr.submit(m), Refusal::None);
      const auto& u = tr.lastUpdate();
      if (u && u->fused_before >= 4) {
        nis_sum += u->nis;
        ++out.nis_samples;
      }
    }
    const estimation::StateEstimate& s = tr.state();
    EXPECT_EQ(s.dim(), 6);  // the reported state is (p, v) with or without the bias
    const Vector6 e = f.truthAt(s.t(), cfg.model) - s.x();
    nees_sum += e.dot(s.P().ldlt().solve(e));
    ++out.tracks;
  }
  out.nees = nees_sum / out.tracks;
  out.nis = nis_sum / out.nis_samples;
  std::printf("pixel bias %.3g px, tau %g s: NEES %.2f [%.2f, %.2f] (%d tracks), NIS %.3f [%.3f, %.3f] (%d images)\n",
              cfg.pixel_bias.sigma_px, cfg.pixel_bias.time_constant_s, out.nees, Consistency::band(6, out.tracks, 0.005),
              Consistency::band(6, out.tracks, 0.995), out.tracks, out.nis, Consistency::band(2, out.nis_samples, 0.005),
              Consistency::band(2, out.nis_samples, 0.995), out.nis_samples);
  return out;
}

}  // namespace

TEST(TrackerPixelBias, WithoutTheBiasStateAPersistentPixelErrorMakesTheNeesTooLarge) {
  const Consistency c = run(baseConfig(), 150, 21);
  EXPECT_GT(c.nees, Consistency::band(6, c.tracks, 0.995)) << "NEES " << c.nees;
}

TEST(TrackerPixelBias, ToldTheTrueBiasAndWhiteNoiseNisAndNeesLieInTheirBands) {
  for (double tau : {std::numeric_limits<double>::infinity(), 1000.0}) {
    TrackerConfig cfg = baseConfig();
    cfg.pixel_bias.sigma_px = kBiasPx;
    cfg.pixel_bias.time_constant_s = tau;  // constant along a track (τ ≫ the flight)
    const Consistency c = run(cfg, 150, 21);
    EXPECT_TRUE(c.inNeesBand()) << "tau " << tau << ": NEES " << c.nees << " over " << c.tracks << " tracks, band ["
                                << Consistency::band(6, c.tracks, 0.005) << ", "
                                << Consistency::band(6, c.tracks, 0.995) << "]";
    EXPECT_TRUE(c.inNisBand()) << "tau " << tau << ": NIS " << c.nis << " over " << c.nis_samples << " images, band ["
                               << Consistency::band(2, c.nis_samples, 0.005) << ", "
                               << Consistency::band(2, c.nis_samples, 0.995) << "]";
  }
}

TEST(TrackerPixelBias, OffIsTheSixStateFilterAndATinyBiasChangesAlmostNothing) {
  const std::vector<core::Camera> cams = rig();
  const TrackerConfig plain = baseConfig();
  TrackerConfig off = plain;
  off.pixel_bias.time_constant_s = 0.3;  // ignored while sigma_px is 0
  TrackerConfig tiny = plain;
  tiny.pixel_bias.sigma_px = 1e-7;
  core::Rng rng = core::makeRng(3);
  std::uint64_t id = 1;
  for (int k = 0; k < 5; ++k) {
    const Flight f = drawFlight(cams, plain, {kBiasPx, kBiasPx}, rng, id);
    ViewlineTracker a(cams, plain), b(cams, off), c(cams, tiny);
    for (const ImageMeasurement& m : f.images) {
      a.submit(m);
      b.submit(m);
      c.submit(m);
      // Off: the same operations, so the same bits.
      ASSERT_EQ(b.trackState().full.dim(), 0);
      ASSERT_TRUE(a.state().x() == b.state().x());
      ASSERT_TRUE(a.state().sqrtP() == b.state().sqrtP());
      ASSERT_EQ(a.lastUpdate()->nis, b.lastUpdate()->nis);
      // A bias of 1e-7 px: the augmented filter (its own predict, update, refit and marginal)
      // gives the six-state result to within what that bias can change.
      ASSERT_EQ(c.trackState().full.dim(), 10);
      ASSERT_EQ(c.state().dim(), 6);
      const Matrix6 Pa = a.state().P(), Pc = c.state().P();
      const Vector6 dx = a.state().x() - c.state().x();
      for (int i = 0; i < 6; ++i) {
        EXPECT_LE(std::abs(dx[i]) / std::sqrt(Pa(i, i)), 1e-4);
        for (int j = 0; j < 6; ++j) EXPECT_LE(std::abs(Pa(i, j) - Pc(i, j)) / std::sqrt(Pa(i, i) * Pa(j, j)), 1e-4);
      }
      EXPECT_NEAR(a.lastUpdate()->nis, c.lastUpdate()->nis, 1e-4 * (1.0 + a.lastUpdate()->nis));
    }
  }
}

TEST(TrackerPixelBias, LateArrivalsGiveExactlyTheInOrderResultWithTheBiasState) {
  const std::vector<core::Camera> cams = rig();
  TrackerConfig cfg = baseConfig();
  cfg.pixel_bias.sigma_px = kBiasPx;
  cfg.pixel_bias.time_constant_s = 2.0;
  core::Rng rng = core::makeRng(8);
  std::uint64_t id = 1;
  for (int k = 0; k < 5; ++k) {
    const Flight f = drawFlight(cams, cfg, {kBiasPx, kBiasPx}, rng, id);
    ViewlineTracker in_order(cams, cfg), late(cams, cfg);
    std::vector<std::pair<double, std::size_t>> arrival;
    for (std::size_t i = 0; i < f.images.size(); ++i) {
      in_order.submit(f.images[i]);
      arrival.emplace_back(f.images[i].t + core::uniform(rng, 0.0, 0.08), i);
    }
    std::sort(arrival.begin(), arrival.end());
    for (const auto& a : arrival) ASSERT_EQ(late.submit(f.images[a.second]), Refusal::None);
    EXPECT_GT(late.lateInserted(), 0u);
    EXPECT_LE((in_order.trackState().full.x() - late.trackState().full.x()).cwiseAbs().maxCoeff(), 1e-12);
    EXPECT_LE((in_order.state().P() - late.state().P()).cwiseAbs().maxCoeff(), 1e-12);
  }
}

TEST(TrackerPixelBias, RobustStartConfirmsAndSetsAsideAnOutlierWithTheBiasState) {
  const std::vector<core::Camera> cams = rig();
  TrackerConfig cfg = baseConfig();
  cfg.pixel_bias.sigma_px = kBiasPx;
  cfg.pixel_bias.time_constant_s = 2.0;
  cfg.start.confirm_images = 5;
  core::Rng rng = core::makeRng(4);
  std::uint64_t id = 1;
  Flight f = drawFlight(cams, cfg, {kBiasPx, kBiasPx}, rng, id);
  f.images[1].uv += Eigen::Vector2d(40.0, -30.0);  // a gross outlier among the first images
  ViewlineTracker tr(cams, cfg);
  for (const ImageMeasurement& m : f.images) tr.submit(m);
  ASSERT_TRUE(tr.confirmed());
  const auto o = tr.outcome(f.images[1].id);
  ASSERT_TRUE(o.has_value());
  EXPECT_NE(o->fate, Fate::Fused);
  const estimation::StateEstimate& s = tr.state();
  const Vector6 e = f.truthAt(s.t(), cfg.model) - s.x();
  EXPECT_LT(e.dot(s.P().ldlt().solve(e)), core::chiSquareQuantile(6, 0.999));
}

TEST(TrackerConfig, PixelBiasFieldsAreChecked) {
  TrackerConfig c = baseConfig();
  c.pixel_bias.sigma_px = -0.1;
  EXPECT_THROW(c.validate(), core::InvalidInput);
  c.pixel_bias.sigma_px = 0.1;
  c.pixel_bias.time_constant_s = 0.0;
  EXPECT_THROW(c.validate(), core::InvalidInput);
  c.pixel_bias.time_constant_s = std::numeric_limits<double>::infinity();
  EXPECT_NO_THROW(c.validate());
}

TEST(TrackerPixelBias, EachCameraItsOwnBiasStd) {
  // Camera 1 keeps a four times larger persistent error (e.g. not registered to the robot).
  const std::vector<double> bias = {0.1, 0.4};
  TrackerConfig cfg = baseConfig();
  cfg.pixel_bias.sigma_px = 0.1;
  cfg.pixel_bias.time_constant_s = std::numeric_limits<double>::infinity();
  const Consistency one = run(cfg, 150, 23, bias);  // both cameras told 0.1 px
  EXPECT_GT(one.nees, Consistency::band(6, one.tracks, 0.995)) << "NEES " << one.nees;
  cfg.pixel_bias.camera_sigma_px = bias;
  const Consistency each = run(cfg, 150, 23, bias);
  EXPECT_TRUE(each.inNeesBand()) << "NEES " << each.nees;
  EXPECT_TRUE(each.inNisBand()) << "NIS " << each.nis;
  // One entry per camera, each > 0.
  cfg.pixel_bias.camera_sigma_px = {0.1};
  EXPECT_THROW(ViewlineTracker(rig(), cfg), core::InvalidInput);
  cfg.pixel_bias.camera_sigma_px = {0.1, 0.0};
  EXPECT_THROW(ViewlineTracker(rig(), cfg), core::InvalidInput);
}
