#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

// The viewline tracker on generated dart flights (the dart scenario's world is the fixture).
#include "viewline/core/error.h"
#include "viewline/core/random.h"
#include "viewline/scenarios/dart/world.h"
#include "viewline/tracking/image_ekf.h"
#include "viewline/tracking/tracker.h"

using namespace viewline;
using namespace viewline::tracking;
using scenarios::DartClockMode;

namespace {

struct Fixture {
  scenarios::DartScenarioConfig cfg = scenarios::defaultDartScenario();
  std::vector<core::Camera> cams = scenarios::makeDartCameras(cfg);
};

scenarios::DartFlight simulateFlight(const scenarios::DartScenarioConfig& cfg, const std::vector<core::Camera>& cams,
                                     DartClockMode mode, double outlier_rate, core::Rng& rng) {
  return scenarios::simulateDartFlight(cfg, cams, mode, outlier_rate, rng);
}

ImageMeasurement inlier(const core::Camera& cam, std::size_t ci, std::uint64_t id, double t, const Eigen::Vector3d& p) {
  const Eigen::Vector3d pc = cam.c_M_w * p;
  return {id, ci, t, exactPixelOf(cam, {pc.x() / pc.z(), pc.y() / pc.z()}), 0.5};
}

}  // namespace

TEST(Tracker, RefusesAbsurdMeasurementsWithACountableReason) {
  Fixture f;
  ViewlineTracker tr(f.cams, f.cfg.tracker);
  const Eigen::Vector3d p(0.5, 0.0, 1.8);
  EXPECT_EQ(tr.submit(inlier(f.cams[0], 0, 1, 1.0, p)), Refusal::None);
  ImageMeasurement m = inlier(f.cams[1], 1, 2, 1.01, p);
  m.t = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(tr.submit(m), Refusal::NonFinite);
  m = inlier(f.cams[1], 1, 3, 1.01, p);
  m.camera = 7;
  EXPECT_EQ(tr.submit(m), Refusal::UnknownCamera);
  m = inlier(f.cams[1], 1, 4, 1.01, p);
  m.uv = {-50.0, 10.0};
  EXPECT_EQ(tr.submit(m), Refusal::OutsideImage);
  m = inlier(f.cams[1], 1, 5, 1.01, p);
  m.sigma_px = 0.0;
  EXPECT_EQ(tr.submit(m), Refusal::BadNoise);
  EXPECT_EQ(tr.submit(inlier(f.cams[0], 0, 6, 1.0, p)), Refusal::Duplicate);  // same camera and stamp
  EXPECT_EQ(tr.submit(inlier(f.cams[1], 1, 1, 1.005, p)), Refusal::Duplicate);  // same id
  EXPECT_EQ(tr.submit(inlier(f.cams[1], 1, 8, 1.0 - 0.25, p)), Refusal::TooOld);  // beyond the 0.2 s horizon
  EXPECT_EQ(tr.submit(inlier(f.cams[1], 1, 9, 1.0 + 1e6, p)), Refusal::FarFuture);
  EXPECT_EQ(tr.submit(inlier(f.cams[1], 1, 10, 0.9, p)), Refusal::None);  // late but within the horizon
  EXPECT_EQ(tr.refusalCount(Refusal::Duplicate), 2u);
  EXPECT_EQ(tr.refusalCount(Refusal::TooOld), 1u);
  EXPECT_EQ(tr.refusalCount(Refusal::FarFuture), 1u);
  EXPECT_EQ(tr.refusalCount(Refusal::NonFinite), 1u);
  EXPECT_EQ(tr.lateInserted(), 1u);
  EXPECT_FALSE(tr.outcome(4).has_value());  // refused measurements are never fused
  EXPECT_TRUE(tr.outcome(10).has_value());
}

TEST(Tracker, LateArrivalsGiveExactlyTheInOrderResult) {
  Fixture f;
  core::Rng rng = core::makeRng(11);
  int compared = 0;
  for (int run = 0; run < 20; ++run) {
    const scenarios::DartFlight fl = simulateFlight(f.cfg, f.cams, DartClockMode::FreeRunning, 0.1, rng);
    ViewlineTracker in_order(f.cams, f.cfg.tracker), late(f.cams, f.cfg.tracker);
    std::vector<std::pair<double, std::size_t>> arrival;
    for (std::size_t i = 0; i < fl.detections.size(); ++i) {
      in_order.submit(fl.detections[i].m);
      arrival.emplace_back(fl.detections[i].m.t + core::uniform(rng, 0.0, 0.1), i);
    }
    std::sort(arrival.begin(), arrival.end());
    for (const auto& a : arrival) EXPECT_EQ(late.submit(fl.detections[a.second].m), Refusal::None);
    ASSERT_TRUE(in_order.initialised());
    EXPECT_GT(late.lateInserted(), 0u);
    EXPECT_LE((in_order.state().x() - late.state().x()).cwiseAbs().maxCoeff(), 1e-12);
    EXPECT_LE((in_order.state().P() - late.state().P()).cwiseAbs().maxCoeff(), 1e-12);
    for (const scenarios::DartDetection& d : fl.detections) {
      const auto a = in_order.outcome(d.m.id), b = late.outcome(d.m.id);
      ASSERT_TRUE(a && b);
      EXPECT_EQ(a->fate, b->fate);
    }
    ++compared;
  }
  EXPECT_EQ(compared, 20);
}

TEST(Tracker, OneBadCameraDoesNotVetoTheOthers) {
  Fixture f;
  core::Rng rng = core::makeRng(5);
  const scenarios::DartFlight fl = simulateFlight(f.cfg, f.cams, DartClockMode::Alternating, 0.0, rng);
  ViewlineTracker tr(f.cams, f.cfg.tracker);
  for (std::size_t i = 0; i + 1 < fl.detections.size(); ++i) tr.submit(fl.detections[i].m);
  const scenarios::DartDetection& last = fl.detections.back();
  const double t = last.m.t;
  const Eigen::Vector3d p = last.truth.head<3>();
  ImageMeasurement bad = inlier(f.cams[0], 0, 1000, t, p);
  bad.uv += Eigen::Vector2d(40.0, -30.0);  // gross error in camera 0
  const ImageMeasurement good = inlier(f.cams[1], 1, 1001, t, p);
  tr.submit(bad);
  tr.submit(good);
  ASSERT_TRUE(tr.outcome(1000) && tr.outcome(1001));
  EXPECT_EQ(tr.outcome(1000)->fate, Fate::Gated);
  EXPECT_TRUE(tr.outcome(1000)->gate.mahalanobis_outlier);
  EXPECT_TRUE(tr.outcome(1000)->gate.directional_outlier);
  EXPECT_EQ(tr.outcome(1001)->fate, Fate::Fused);
  EXPECT_LT((tr.state().x().head<3>() - p).norm(), 0.02);
}

TEST(Tracker, ABiasedThirdCameraIsOutvotedByTheTwoThatAgreeAndDoesNotRestartTheTrack) {
  // Cameras 0 and 1 as the dart rig; camera 2 at camera 0's pose, 4 px off (an unregistered
  // camera), joining once the track is determined: its images are rejected, and the two others,
  // which agree with the track, keep it (without outvoting, its third rejection restarts it).
  Fixture f;
  core::Rng rng = core::makeRng(5);
  const scenarios::DartFlight fl = simulateFlight(f.cfg, f.cams, DartClockMode::Alternating, 0.0, rng);
  std::vector<core::Camera> cams = f.cams;
  cams.push_back(f.cams[0]);
  ViewlineTracker tr(cams, f.cfg.tracker);
  std::uint64_t id = 100000;
  std::size_t biased_gated = 0, biased = 0;
  for (const scenarios::DartDetection& d : fl.detections) {
    tr.submit(d.m);
    if (d.m.camera != 0 || tr.trackState().fused_in_track < 10) continue;
    ImageMeasurement b = inlier(cams[2], 2, id++, d.m.t, d.truth.head<3>());
    b.uv += Eigen::Vector2d(4.0, 0.0);
    tr.submit(b);
    ++biased;
    biased_gated += tr.outcome(b.id)->fate != Fate::Fused;
  }
  EXPECT_EQ(tr.trackState().restarts, 0);
  EXPECT_GE(biased, 3u);
  EXPECT_EQ(biased_gated, biased);
  EXPECT_LT((tr.state().x().head<3>() - fl.detections.back().truth.head<3>()).norm(), 0.02);
}

TEST(Tracker, TrackSeededByAnOutlierIsRestartedAndTheOutlierDropped) {
  Fixture f;
  core::Rng rng = core::makeRng(9);
  const scenarios::DartFlight fl = simulateFlight(f.cfg, f.cams, DartClockMode::Alternating, 0.0, rng);
  ViewlineTracker tr(f.cams, f.cfg.tracker);
  ImageMeasurement seed = fl.detections.front().m;
  seed.id = 999;
  seed.t -= 0.005;
  seed.uv = {600.0, 40.0};  // far from the dart
  ASSERT_EQ(tr.submit(seed), Refusal::None);
  for (const scenarios::DartDetection& d : fl.detections) tr.submit(d.m);
  EXPECT_GE(tr.trackState().restarts, 1);
  ASSERT_TRUE(tr.outcome(999).has_value());
  EXPECT_EQ(tr.outcome(999)->fate, Fate::DroppedOnRestart);
  EXPECT_LT((tr.state().x().head<3>() - fl.detections.back().truth.head<3>()).norm(), 0.02);
  std::size_t inliers_rejected = 0;
  for (const scenarios::DartDetection& d : fl.detections) inliers_rejected += tr.outcome(d.m.id)->fate != Fate::Fused;
  EXPECT_LE(inliers_rejected, 1u);  // the re-fed history recovers the inliers the bad track had gated
}

TEST(Tracker, DtOffsetRowsEqualExactPropagationForImagesOnTheGrid) {
  Fixture f;
  core::Rng rng = core::makeRng(3);
  const scenarios::DartFlight fl = simulateFlight(f.cfg, f.cams, DartClockMode::Alternating, 0.0, rng);  // t = k * 10 ms
  TrackerConfig exact = f.cfg.tracker, offset = f.cfg.tracker;
  offset.time_mode = TimeMode::DtOffset;
  offset.sample_period = 0.01;
  ViewlineTracker a(f.cams, exact), b(f.cams, offset);
  for (const scenarios::DartDetection& d : fl.detections) {
    a.submit(d.m);
    b.submit(d.m);
  }
  EXPECT_LT((a.state().x() - b.state().x()).norm(), 1e-6);
  // With a 20 ms grid half of the images are 10 ms off-grid; without process noise and with the
  // ½ g Δt² term the rows are still exact, so the estimates agree closely.
  offset.sample_period = 0.02;
  ViewlineTracker c(f.cams, offset);
  for (const scenarios::DartDetection& d : fl.detections) c.submit(d.m);
  EXPECT_LT((c.predictAt(a.state().t()).x().head<3>() - a.state().x().head<3>()).norm(), 1e-4);
}

TEST(ImageEkf, TracksCleanDataFromANearPrior) {
  Fixture f;
  core::Rng rng = core::makeRng(21);
  const scenarios::DartFlight fl = simulateFlight(f.cfg, f.cams, DartClockMode::Alternating, 0.0, rng);
  TrackerConfig cfg = f.cfg.tracker;
  cfg.prior_mean = fl.detections.front().truth;
  cfg.prior_mean.head<3>() += Eigen::Vector3d(0.1, -0.1, 0.05);
  cfg.prior_cov = 0.5 * Matrix6::Identity();
  ImageSpaceEkf ekf(f.cams, cfg);
  for (const scenarios::DartDetection& d : fl.detections) EXPECT_EQ(ekf.submit(d.m), Refusal::None);
  EXPECT_LT((ekf.state().x().head<3>() - fl.detections.back().truth.head<3>()).norm(), 0.02);
  ImageMeasurement old = fl.detections.front().m;
  EXPECT_EQ(ekf.submit(old), Refusal::TooOld);
}

TEST(TrackerConfig, InvalidFieldsAreNamed) {
  TrackerConfig cfg;
  cfg.restart_after_rejections = 0;
  try {
    cfg.validate();
    FAIL() << "expected InvalidInput";
  } catch (const core::InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("restart_after_rejections"), std::string::npos);
  }
}

TEST(Tracker, ReportsEachImagesGateDecisionAndItsOwnInnovation) {
  Fixture f;
  core::Rng rng = core::makeRng(9);
  const scenarios::DartFlight fl = simulateFlight(f.cfg, f.cams, DartClockMode::Alternating, 0.0, rng);
  ViewlineTracker tr(f.cams, f.cfg.tracker);
  ImageMeasurement seed = fl.detections.front().m;
  seed.id = 999;
  seed.t -= 0.005;
  seed.uv = {600.0, 40.0};  // far from the dart: the track it seeds rejects the next images
  ASSERT_EQ(tr.submit(seed), Refusal::None);
  ASSERT_TRUE(tr.lastUpdate());
  EXPECT_EQ(tr.lastUpdate()->decision, GateDecision::Start);
  EXPECT_EQ(tr.lastUpdate()->fused_before, 0);
  std::map<GateDecision, int> seen;
  for (const scenarios::DartDetection& d : fl.detections) {
    ASSERT_EQ(tr.submit(d.m), Refusal::None);
    ASSERT_TRUE(tr.lastUpdate());
    const ImageUpdate& u = *tr.lastUpdate();
    EXPECT_EQ(u.m.id, d.m.id);
    ++seen[u.decision];
    if (u.decision == GateDecision::Accept) {
      // The reported NIS is the one the gate tested: dᵀ S⁻¹ d within the chi-square threshold.
      EXPECT_NEAR(u.nis, u.innovation.dot(u.S.ldlt().solve(u.innovation)), 1e-9 * (1.0 + u.nis));
      EXPECT_EQ(tr.outcome(d.m.id)->decision, GateDecision::Accept);
    }
  }
  // restart_after_rejections = 3 rejections of one camera in a row restart the track once.
  EXPECT_LE(seen[GateDecision::Restart], tr.trackState().restarts);  // re-fed images may restart too
  EXPECT_GE(seen[GateDecision::Restart], 1);
  EXPECT_GE(seen[GateDecision::Reject], 1);
  EXPECT_GT(seen[GateDecision::Accept], 5);
  ImageMeasurement bad = fl.detections.back().m;
  bad.uv = {-50.0, 10.0};
  EXPECT_EQ(tr.submit(bad), Refusal::OutsideImage);
  EXPECT_FALSE(tr.lastUpdate());  // a refused image is not processed
}

TEST(Tracker, ResetForgetsTheTrackAndTheLastUpdate) {
  Fixture f;
  core::Rng rng = core::makeRng(4);
  const scenarios::DartFlight fl = simulateFlight(f.cfg, f.cams, DartClockMode::Alternating, 0.0, rng);
  ViewlineTracker a(f.cams, f.cfg.tracker), b(f.cams, f.cfg.tracker);
  for (const scenarios::DartDetection& d : fl.detections) a.submit(d.m);
  a.reset();
  EXPECT_FALSE(a.initialised());
  EXPECT_FALSE(a.lastUpdate());
  for (const scenarios::DartDetection& d : fl.detections) {
    a.submit(d.m);
    b.submit(d.m);
  }
  EXPECT_EQ((a.state().x() - b.state().x()).cwiseAbs().maxCoeff(), 0.0);  // a reset tracker is a new one
}

TEST(Tracker, RobustStartSetsAsideAnOutlierSeedAndReportsOnlyAConfirmedTrack) {
  Fixture f;
  core::Rng rng = core::makeRng(9);
  const scenarios::DartFlight fl = simulateFlight(f.cfg, f.cams, DartClockMode::Alternating, 0.0, rng);
  TrackerConfig tc = f.cfg.tracker;
  tc.start.confirm_images = 5;
  ViewlineTracker tr(f.cams, tc);
  ImageMeasurement seed = fl.detections.front().m;
  seed.id = 999;
  seed.t -= 0.005;
  seed.uv = {600.0, 40.0};  // far from the dart
  ASSERT_EQ(tr.submit(seed), Refusal::None);
  EXPECT_TRUE(tr.initialised());
  EXPECT_FALSE(tr.confirmed());  // one image: nothing to test it against
  std::size_t confirmed_at = 0;
  for (std::size_t i = 0; i < fl.detections.size(); ++i) {
    tr.submit(fl.detections[i].m);
    if (tr.confirmed() && confirmed_at == 0) {
      confirmed_at = i + 1;
      // Confirmed on the inliers alone: the estimate is already on the flight.
      EXPECT_LT((tr.state().x().head<3>() - fl.detections[i].truth.head<3>()).norm(), 0.05);
    }
  }
  EXPECT_EQ(confirmed_at, 5u);  // the 5 consistent inliers, the outlier set aside
  EXPECT_EQ(tr.trackState().restarts, 0);
  ASSERT_TRUE(tr.outcome(999).has_value());
  EXPECT_NE(tr.outcome(999)->fate, Fate::Fused);
  for (const scenarios::DartDetection& d : fl.detections) EXPECT_EQ(tr.outcome(d.m.id)->fate, Fate::Fused);
  EXPECT_LT((tr.state().x().head<3>() - fl.detections.back().truth.head<3>()).norm(), 0.02);
}

TEST(Tracker, WithoutTheRobustStartTheFirstImageGivesAConfirmedTrack) {
  Fixture f;
  core::Rng rng = core::makeRng(9);
  const scenarios::DartFlight fl = simulateFlight(f.cfg, f.cams, DartClockMode::Alternating, 0.0, rng);
  ViewlineTracker tr(f.cams, f.cfg.tracker);
  ASSERT_EQ(f.cfg.tracker.start.confirm_images, 0);
  tr.submit(fl.detections.front().m);
  EXPECT_TRUE(tr.confirmed());
}

TEST(TrackerConfig, RobustStartNeedsAWindowForItsSubsets) {
  TrackerConfig tc;
  tc.start.confirm_images = 5;
  tc.start.max_outliers = 2;
  tc.start.window = 6;
  EXPECT_THROW(tc.validate(), core::InvalidInput);
  tc.start.window = 7;
  EXPECT_NO_THROW(tc.validate());
}
