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
