#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>

#include "viewline/core/frames.h"
#include "viewline/core/random.h"
#include "viewline/estimation/discretization.h"
#include "viewline/estimation/kalman_filter.h"
#include "viewline/tracking/gates.h"
#include "viewline/tracking/tracker.h"
#include "viewline/tracking/viewline.h"

using namespace viewline;
using namespace viewline::tracking;

namespace {

core::Camera makeCamera(const Eigen::Vector3d& eye, const Eigen::Vector3d& target, double kud) {
  core::Camera cam;
  cam.width = 656;
  cam.height = 480;
  const vpCameraParameters pin = core::intrinsicsFromFov(core::deg2rad(62.0), 656, 480);
  cam.intrinsics = kud == 0.0 ? pin
                              : vpCameraParameters(pin.get_px(), pin.get_py(), pin.get_u0(), pin.get_v0(), kud, -kud);
  cam.c_M_w = core::lookAt(eye, target, Eigen::Vector3d::UnitZ());
  return cam;
}

Eigen::Vector2d pixelOf(const core::Camera& cam, const Eigen::Vector3d& p) {
  const Eigen::Vector3d pc = cam.c_M_w * p;
  return exactPixelOf(cam, {pc.x() / pc.z(), pc.y() / pc.z()});
}

}  // namespace

TEST(Viewline, PlanesAreNormalisedContainTheCameraCentreAndTheObject) {
  for (double kud : {0.0, 0.05}) {
    const core::Camera cam = makeCamera({1.2, -2.6, 1.6}, {1.2, 0.0, 1.75}, kud);
    const Eigen::Vector3d p(1.9, 0.3, 2.1);  // off-centre: distortion matters
    const ViewlinePlanes pl = viewlinePlanes(cam, pixelOf(cam, p));
    for (const Eigen::Vector4d& pi : {pl.pi_x, pl.pi_y}) {
      EXPECT_NEAR(pi.head<3>().norm(), 1.0, 1e-12);
      EXPECT_NEAR(pi.head<3>().dot(p) + pi[3], 0.0, 1e-9) << "object on the plane (kud " << kud << ")";
      EXPECT_NEAR(pi.head<3>().dot(cam.center_w()) + pi[3], 0.0, 1e-9) << "camera centre on the plane";
    }
    // The viewline is the planes' intersection: along the ray through the pixel.
    const Eigen::Vector3d ray = (p - cam.center_w()).normalized();
    EXPECT_NEAR(std::abs(pl.direction_w().dot(ray)), 1.0, 1e-10);
  }
}

TEST(Viewline, RowsGiveTheMeasurementExactlyAndShiftedRowsFollowEq26) {
  const core::Camera cam = makeCamera({1.2, -2.6, 1.6}, {1.2, 0.0, 1.75}, 0.03);
  BallisticModel model;
  Vector6 x;
  x << 0.5, 0.1, 1.8, 13.0, -0.4, 1.5;
  const Matrix6 P = Matrix6::Identity();
  // Image captured exactly at the state time.
  ViewlineRows r = viewlineRows(cam, pixelOf(cam, x.head<3>()), 0.5, x, P, 0.0, model);
  EXPECT_LT((r.C * x - r.y).norm(), 1e-9);
  EXPECT_EQ(r.C.rightCols<3>().norm(), 0.0);
  // Image captured dt later: the rows of [L] eq 26 (with the ½ g dt² term) hold exactly for a ballistic flight.
  const double dt = 0.013;
  const Vector6 x_later = model.propagate(x, dt);
  r = viewlineRows(cam, pixelOf(cam, x_later.head<3>()), 0.5, x, P, dt, model);
  EXPECT_LT((r.C * x - r.y).norm(), 1e-9);
  EXPECT_LT((r.C.rightCols<3>() - dt * r.C.leftCols<3>()).norm(), 1e-15);
}

TEST(Viewline, RowNoiseMatchesMonteCarloAndRowsAreIndependentWithoutDistortion) {
  const core::Camera cam = makeCamera({1.2, -2.6, 1.6}, {1.2, 0.0, 1.75}, 0.0);
  const Eigen::Vector3d p(2.0, 0.4, 2.2);  // x, y far from 0 so the √(1+x²) factors matter
  const Eigen::Vector3d pc = cam.c_M_w * p;
  const Eigen::Vector2d uv = pixelOf(cam, p);
  const double sigma = 0.5;
  const ViewlinePlanes pl0 = viewlinePlanes(cam, uv);
  const Eigen::Matrix2d R = viewlineRowNoise(cam, uv, pl0, sigma, pc.z() * pc.z());
  core::Rng rng = core::makeRng(7);
  const int n = 40000;
  Eigen::Matrix2d emp = Eigen::Matrix2d::Zero();
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector2d uvn = uv + Eigen::Vector2d(core::gaussian(rng, sigma), core::gaussian(rng, sigma));
    const ViewlinePlanes pl = viewlinePlanes(cam, uvn);
    const Eigen::Vector2d e(-(pl.pi_x.head<3>().dot(p) + pl.pi_x[3]), -(pl.pi_y.head<3>().dot(p) + pl.pi_y[3]));
    emp += e * e.transpose();
  }
  emp /= n;
  EXPECT_NEAR(emp(0, 0) / R(0, 0), 1.0, 0.03);
  EXPECT_NEAR(emp(1, 1) / R(1, 1), 1.0, 0.03);
  EXPECT_LT(std::abs(emp(0, 1)) / std::sqrt(emp(0, 0) * emp(1, 1)), 0.03);  // independent rows
  EXPECT_EQ(R(0, 1), 0.0);
  // The small-angle form (σ Z / f)² is the same up to the 1/(1+x²) factor.
  const double f = cam.intrinsics.get_px();
  const double x = pc.x() / pc.z();
  EXPECT_NEAR(R(0, 0), std::pow(sigma * pc.z() / f, 2) / (1.0 + x * x), 1e-12 * R(0, 0) + 1e-15);
}

TEST(Viewline, StackedUpdateEqualsImageByImageUpdate) {
  const std::vector<core::Camera> cams = {makeCamera({1.2, -2.6, 1.6}, {1.2, 0.0, 1.75}, 0.02),
                                          makeCamera({-0.9, 1.9, 2.3}, {1.3, 0.0, 1.7}, -0.02),
                                          makeCamera({2.5, 2.5, 2.5}, {1.0, 0.0, 1.7}, 0.0)};
  BallisticModel model;
  Vector6 x;
  x << 1.0, 0.0, 1.8, 12.0, 0.0, 0.5;
  const Matrix6 P = 0.3 * Matrix6::Identity();
  const Eigen::Vector3d p_true(1.1, 0.05, 1.76);
  std::vector<ViewlineRows> rows;
  for (const auto& c : cams) rows.push_back(viewlineRows(c, pixelOf(c, p_true), 0.5, x, P, 0.0, model));
  estimation::StateEstimate a(x, P), b(x, P);
  estimation::update(a, stackRows(rows));
  for (const auto& r : rows) estimation::update(b, estimation::LinearMeasurement{r.C, r.y, r.R});
  EXPECT_LT((a.x() - b.x()).norm(), 1e-10);
  EXPECT_LT((a.P() - b.P()).norm(), 1e-12);
  // Zero images: a 0-row measurement, predict only.
  const estimation::LinearMeasurement none = stackRows({});
  EXPECT_EQ(none.y.size(), 0);
  estimation::StateEstimate c(x, P);
  estimation::update(c, none);
  EXPECT_EQ((c.x() - x).norm(), 0.0);
}

TEST(Viewline, NeedleCovarianceAlongTheViewlineAfterTheFirstMeasurement) {
  // [L] Fig. 6: after one image the position uncertainty collapses to a line along that viewline.
  const core::Camera cam = makeCamera({1.2, -2.6, 1.6}, {1.2, 0.0, 1.75}, 0.03);
  TrackerConfig cfg;
  cfg.prior_mean << 1.0, 0.0, 1.75, 12.0, 0.0, 0.0;
  ViewlineTracker tr({cam}, cfg);
  const Eigen::Vector3d p(0.4, 0.1, 1.8);
  ASSERT_EQ(tr.submit({1, 0, 0.0, pixelOf(cam, p), 0.5}), Refusal::None);
  const Eigen::Matrix3d Pp = tr.state().P().topLeftCorner<3, 3>();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(Pp);
  const Eigen::Vector3d ev = es.eigenvalues();  // ascending
  EXPECT_GE(std::sqrt(ev(2)), 10.0 * std::sqrt(ev(1)));
  const Eigen::Vector3d axis = es.eigenvectors().col(2);
  const Eigen::Vector3d ray = (p - cam.center_w()).normalized();
  EXPECT_LE(core::rad2deg(std::acos(std::min(1.0, std::abs(axis.dot(ray))))), 2.0);
}

TEST(Ballistic, TransitionEqualsVanLoanDiscretisation) {
  BallisticModel m;
  m.gravity_w = {0.0, 0.0, -9.81};
  m.accel_psd = 0.7;
  estimation::ContinuousLinearModel c;
  c.A = Eigen::MatrixXd::Zero(6, 6);
  c.A.topRightCorner(3, 3).setIdentity();
  c.B = Eigen::MatrixXd::Zero(6, 3);
  c.B.bottomRows(3).setIdentity();
  c.G = c.B;
  c.Qc = 0.7 * Eigen::MatrixXd::Identity(3, 3);
  for (double dt : {0.001, 0.02, 0.37, 2.0}) {
    const estimation::LinearTransition a = m.transition(dt);
    const estimation::LinearTransition b = estimation::discretize(c, dt, m.gravity_w);
    EXPECT_LT((a.Phi - b.Phi).norm(), 1e-12);
    EXPECT_LT((a.Gamma * a.u - b.Gamma * b.u).norm(), 1e-10);
    EXPECT_LT((a.Q - b.Q).norm(), 1e-10 * std::max(1.0, b.Q.norm()));
  }
  EXPECT_THROW(m.transition(-0.1), core::InvalidInput);
}

TEST(Gates, DirectionalAndMahalanobisReportWhatAndWhy) {
  GateConfig cfg;
  cfg.directional_p = 3.0;
  cfg.mahalanobis_alpha = 1e-3;  // χ²(2) threshold 13.8
  const Eigen::Matrix2d R = (Eigen::Matrix2d() << 4.0, 0.0, 0.0, 0.01).finished();
  // Along the large-variance axis: 5 = 2.5 σ -> both accept.
  GateReport g = evaluateGate(Eigen::Vector2d(5.0, 0.0), R, cfg);
  EXPECT_FALSE(g.directional_outlier);
  EXPECT_FALSE(g.mahalanobis_outlier);
  EXPECT_NEAR(g.sigma_dir, 2.0, 1e-12);
  EXPECT_NEAR(g.mahalanobis, 6.25, 1e-12);
  // Along the small axis: 0.5 = 5 σ -> both reject.
  g = evaluateGate(Eigen::Vector2d(0.0, 0.5), R, cfg);
  EXPECT_TRUE(g.directional_outlier);
  EXPECT_TRUE(g.mahalanobis_outlier);
  EXPECT_TRUE(g.rejected);
  EXPECT_NE(g.reason().find("mahalanobis"), std::string::npos);
  // Oblique: the directional σ is dominated by the large axis, the Mahalanobis test is not.
  g = evaluateGate(Eigen::Vector2d(3.0, 0.5), R, cfg);
  EXPECT_FALSE(g.directional_outlier);
  EXPECT_TRUE(g.mahalanobis_outlier);
  cfg.kind = GateKind::Directional;
  EXPECT_FALSE(evaluateGate(Eigen::Vector2d(3.0, 0.5), R, cfg).rejected);
  EXPECT_THROW(gateKindFromString("chi2"), core::InvalidInput);
}
