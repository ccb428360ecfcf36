// The ball-catching flight fit: a drag-model batch fit of two cameras' images of a thrown ball.
// Exact pixels give back the true state; with 0.5 px noise its error matches its covariance and is
// far below what the images' noise gives one at a time; a ball seen by one camera only is not used.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "viewline/core/error.h"
#include "viewline/core/random.h"
#include "viewline/scenarios/ball_catching.h"

using namespace viewline;
using Vec6 = Eigen::Matrix<double, 6, 1>;

namespace {

std::vector<core::Camera> twoCameras() {
  scenarios::CatchCameraConfig a, b;
  a.position = Eigen::Vector3d(4.6, -2.9, 2.1);  // the catching rig's `right` and `behind`, roughly
  a.look_at = Eigen::Vector3d(2.4, 0.0, 1.3);
  a.kud = 0.02;
  b.position = Eigen::Vector3d(5.5, 1.5, 1.8);
  b.look_at = Eigen::Vector3d(2.0, 0.0, 1.2);
  return {a.renderCamera(), b.renderCamera()};
}

estimation::DragBallisticModel ballModel() {
  estimation::DragBallisticModel m;
  m.k = 0.0103;  // the 5 cm, 57 g ball
  m.q = 0.0;
  return m;
}

struct Flight {
  std::vector<scenarios::FitImage> images;
  std::vector<Vec6> truth;  ///< state at each image
};

// A throw from (0, 0.1, 1.3) at 7.5 m/s, imaged alternately by the two cameras at 100 Hz overall.
Flight throwFlight(const std::vector<core::Camera>& cams, double noise_px, core::Rng& rng) {
  const estimation::DragBallisticModel m = ballModel();
  Vec6 x;
  x << 0.0, 0.1, 1.3, 7.5, -0.2, 1.8;
  Flight f;
  const double dt = 0.01;
  for (int i = 0; i < 45; ++i) {
    if (i > 0) x = m.propagateFixed(x, dt);
    scenarios::FitImage img;
    img.camera = static_cast<std::size_t>(i % 2);
    img.t = i * dt;
    const auto uv = cams[img.camera].project(x.head<3>());
    EXPECT_TRUE(uv.has_value());
    img.uv = *uv;
    for (int k = 0; k < 2; ++k) img.uv(k) += noise_px * core::gaussian(rng);
    img.sigma_px = noise_px > 0.0 ? noise_px : 0.3;
    f.images.push_back(img);
    f.truth.push_back(x);
  }
  return f;
}

// The tracker's estimate as a rough seed: the truth off by 5 cm and 0.3 m/s.
estimation::StateEstimate roughGuess(const Vec6& x, double t) {
  Vec6 g = x;
  g.head<3>() += Eigen::Vector3d(0.05, -0.03, 0.04);
  g.tail<3>() += Eigen::Vector3d(-0.3, 0.2, 0.1);
  return estimation::StateEstimate(g, Eigen::Matrix<double, 6, 6>::Identity(), t);
}

}  // namespace

TEST(FlightFit, ExactPixelsGiveBackTheTrueState) {
  const auto cams = twoCameras();
  core::Rng rng = core::makeRng(1);
  const Flight f = throwFlight(cams, 0.0, rng);
  scenarios::FlightFit fit({}, cams, ballModel());
  std::optional<estimation::StateEstimate> est;
  for (std::size_t i = 0; i < f.images.size(); ++i) {
    est = fit.add(f.images[i], roughGuess(f.truth[i], f.images[i].t));
    if (i + 1 < 8) {
      EXPECT_FALSE(est.has_value()) << "used before min_images";
    }
  }
  ASSERT_TRUE(est.has_value());
  EXPECT_DOUBLE_EQ(est->t(), f.images.back().t);
  EXPECT_LT((est->x().head<3>() - f.truth.back().head<3>()).norm(), 1e-6);
  EXPECT_LT((est->x().tail<3>() - f.truth.back().tail<3>()).norm(), 1e-5);
}

TEST(FlightFit, NoisyPixelsErrorMatchesItsCovariance) {
  const auto cams = twoCameras();
  core::Rng rng = core::makeRng(2);
  double nees = 0.0, err_mm = 0.0;
  const int trials = 40;
  for (int k = 0; k < trials; ++k) {
    const Flight f = throwFlight(cams, 0.5, rng);
    scenarios::FlightFit fit({}, cams, ballModel());
    std::optional<estimation::StateEstimate> est;
    for (std::size_t i = 0; i < f.images.size(); ++i) est = fit.add(f.images[i], roughGuess(f.truth[i], f.images[i].t));
    ASSERT_TRUE(est.has_value());
    const Eigen::Vector3d e = est->x().head<3>() - f.truth.back().head<3>();
    nees += e.dot(est->P().topLeftCorner<3, 3>().ldlt().solve(e)) / trials;
    err_mm += 1e3 * e.norm() / trials;
  }
  EXPECT_GT(nees, 3.0 * 0.6);  // chi-square(3) mean 3; 40 trials: within ±40 %
  EXPECT_LT(nees, 3.0 * 1.4);
  EXPECT_LT(err_mm, 2.0);  // one 0.5 px image at ~4 m is ~4 mm along each image axis
}

TEST(FlightFit, OneCameraIsNotUsedAndANewTrackStartsOver) {
  const auto cams = twoCameras();
  core::Rng rng = core::makeRng(3);
  Flight f = throwFlight(cams, 0.0, rng);
  scenarios::FlightFit fit({}, cams, ballModel());
  for (std::size_t i = 0; i < 20; ++i) {
    scenarios::FitImage one = f.images[i];
    if (one.camera != 0) continue;
    EXPECT_FALSE(fit.add(one, roughGuess(f.truth[i], one.t)).has_value()) << "one viewline";
  }
  fit.reset();
  EXPECT_EQ(fit.images(), 0u);
  EXPECT_THROW(fit.add({5, 0.0, Eigen::Vector2d::Zero(), 1.0}, roughGuess(f.truth[0], 0.0)), core::InvalidInput);
  scenarios::FlightFitConfig bad;
  bad.min_images = 5;
  EXPECT_THROW(scenarios::FlightFit(bad, cams, ballModel()), core::InvalidInput);
}

namespace {

// The prior of the test throw's envelope: the state at the first image and the aim disc around
// the point where throwFlight's throw crosses x = 4 m (its "home").
scenarios::FlightFitConfig priorConfig() {
  scenarios::FlightFitConfig c;
  c.min_images = 1;
  c.min_cameras = 1;
  c.prior_mean << 0.05, 0.0, 1.32, 7.6, 0.0, 2.3;
  c.prior_std << 0.6, 0.18, 0.18, 1.0, 0.7, 1.0;
  c.aim_prior_std = 0.15;
  return c;
}

// In-plane crossing of the box plane x = 4 m by the drag flight from state x.
Eigen::Vector2d crossingYZ(const Vec6& x) {
  const estimation::DragBallisticModel m = ballModel();
  Vec6 s = x;
  while (s(0) < 4.0) s = m.propagateFixed(s, 0.001);
  return s.segment<2>(1);
}

}  // namespace

// With the throws' prior the fit answers from the first image on (no six-image wait), and a
// handful of noisy images already pull the crossing from the prior's guess (the aim centre)
// to within a few centimetres; with many exact images the prior's pull is gone.
TEST(FlightFit, ThrowPriorGivesACrossingFromTheFirstImage) {
  const auto cams = twoCameras();
  const scenarios::FitAimPlane aim{Eigen::Vector3d(4.0, 0.0, 1.1), Eigen::Vector3d(-1.0, 0.0, 0.0)};
  core::Rng rng = core::makeRng(4);
  const Flight exact = throwFlight(cams, 0.0, rng);
  const Eigen::Vector2d truth = crossingYZ(exact.truth.front());
  ASSERT_GT((truth - Eigen::Vector2d(0.0, 1.1)).norm(), 0.05) << "the throw must not aim at the prior's centre";
  {
    scenarios::FlightFit fit(priorConfig(), cams, ballModel(), aim);
    const auto first = fit.add(exact.images[0], roughGuess(exact.truth[0], exact.images[0].t));
    ASSERT_TRUE(first.has_value()) << "the prior determines the state from the first image";
    std::optional<estimation::StateEstimate> est;
    for (std::size_t i = 1; i < exact.images.size(); ++i)
      est = fit.add(exact.images[i], roughGuess(exact.truth[i], exact.images[i].t));
    ASSERT_TRUE(est.has_value());
    EXPECT_LT((est->x().head<3>() - exact.truth.back().head<3>()).norm(), 1e-3);  // 45 exact images outweigh it
  }
  // Eight images with 0.3 px noise (80 ms): the crossing has moved most of the way from the prior's
  // guess (0.26 m off) to the truth, and the truth is within the fit's own 3 σ.
  double err = 0.0;
  int inside = 0;
  const int trials = 20;
  for (int k = 0; k < trials; ++k) {
    const Flight f = throwFlight(cams, 0.3, rng);
    scenarios::FlightFit fit(priorConfig(), cams, ballModel(), aim);
    std::optional<estimation::StateEstimate> est;
    for (std::size_t i = 0; i < 8; ++i) est = fit.add(f.images[i], roughGuess(f.truth[i], f.images[i].t));
    ASSERT_TRUE(est.has_value());
    const Eigen::Vector2d c = crossingYZ(est->x());
    err += (c - truth).norm() / trials;
    // Crossing-point spread from the estimate's covariance (sampled: the fit's own belief).
    core::Rng s_rng = core::makeRng(100 + static_cast<std::uint64_t>(k));
    const Eigen::LLT<Eigen::Matrix<double, 6, 6>> L(est->P());
    Eigen::Vector2d mean = Eigen::Vector2d::Zero(), sq = Eigen::Vector2d::Zero();
    const int draws = 30;
    for (int j = 0; j < draws; ++j) {
      Vec6 z;
      for (int i = 0; i < 6; ++i) z(i) = core::gaussian(s_rng);
      const Eigen::Vector2d cj = crossingYZ(est->x() + L.matrixL() * z);
      mean += cj / draws;
      sq += cj.cwiseProduct(cj) / draws;
    }
    const Eigen::Vector2d sd = (sq - mean.cwiseProduct(mean)).cwiseMax(0.0).cwiseSqrt();
    inside += std::abs(c(0) - truth(0)) <= 3.0 * sd(0) + 1e-3 && std::abs(c(1) - truth(1)) <= 3.0 * sd(1) + 1e-3;
  }
  EXPECT_LT(err, 0.2 * (truth - Eigen::Vector2d(0.0, 1.1)).norm());
  EXPECT_GE(inside, trials - 2);
  scenarios::FlightFitConfig bad = priorConfig();
  bad.prior_std(2) = -1.0;
  EXPECT_THROW(scenarios::FlightFit(bad, cams, ballModel(), aim), core::InvalidInput);
}
