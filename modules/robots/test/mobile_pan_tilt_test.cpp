#include "viewline/robots/mobile_pan_tilt.h"

#include <gtest/gtest.h>

#include <cmath>

#include "viewline/core/error.h"
#include "viewline/core/frames.h"
#include "viewline/core/random.h"

namespace viewline::robots {
namespace {

// Standard DH matrix written out by hand (independent of dhTransform's ViSP products).
Eigen::Matrix4d dhByHand(const DhRow& r) {
  const double ct = std::cos(r.theta), st = std::sin(r.theta), ca = std::cos(r.alpha), sa = std::sin(r.alpha);
  Eigen::Matrix4d m;
  m << ct, -st * ca, st * sa, r.a * ct,  //
      st, ct * ca, -ct * sa, r.a * st,   //
      0, sa, ca, r.d,                    //
      0, 0, 0, 1;
  return m;
}

TEST(MobilePanTilt, DhTransformMatchesTheTextbookMatrix) {
  core::Rng rng = core::makeRng(3);
  for (int i = 0; i < 50; ++i) {
    const DhRow row{core::uniform(rng, -3, 3), core::uniform(rng, -1, 1), core::uniform(rng, -1, 1),
                    core::uniform(rng, -3, 3)};
    const Eigen::Matrix4d ours = core::toEigen(dhTransform(row)).matrix();
    EXPECT_LT((ours - dhByHand(row)).cwiseAbs().maxCoeff(), 1e-12);
  }
}

TEST(MobilePanTilt, ClosedFormCameraCentreEqualsTheCorrectedDhChain) {
  const MobilePanTilt head;
  for (double tilt = -0.5; tilt <= 1.4; tilt += 0.1) {
    for (double pan = -2.9; pan <= 2.9; pan += 0.2) {
      const PanTiltJoints q{tilt, pan};
      const Eigen::Vector3d chain = head.r_M_link4(q).translation();
      EXPECT_LT((chain - head.cameraCenter(q)).norm(), 1e-12) << tilt << " " << pan;
      EXPECT_LT((head.r_M_c(q).translation() - head.cameraCenter(q)).norm(), 1e-12);
    }
  }
}

TEST(MobilePanTilt, PrintedTableDisagreesWithTheClosedForm) {
  // The erratum documented in the header: the literal SPEC table gives another point.
  const MobilePanTilt head;
  const auto& p = head.params();
  const PanTiltJoints q{0.3, 0.2};
  const Eigen::Vector3d printed = core::toEigen(dhChain(head.dhTablePrinted(q))).translation();
  EXPECT_GT((printed - head.cameraCenter(q)).norm(), 0.05);
  const double sa = std::sin(q.tilt), ca = std::cos(q.tilt), sb = std::sin(q.pan), cb = std::cos(q.pan);
  const Eigen::Vector3d expected(p.l2 * sa - p.l3 * ca * cb, p.l3 * sb, p.l1 - p.l2 * ca - p.l3 * sa * cb);
  EXPECT_LT((printed - expected).norm(), 1e-12);
}

TEST(MobilePanTilt, HomePoseLooksStraightAheadLevel) {
  const MobilePanTilt head;
  const Eigen::Isometry3d m = head.r_M_c({0.0, 0.0});
  const auto& p = head.params();
  EXPECT_LT((m.translation() - Eigen::Vector3d(p.l3, 0, p.l1 + p.l2)).norm(), 1e-12);
  EXPECT_LT((m.linear().col(2) - Eigen::Vector3d::UnitX()).norm(), 1e-12);   // optical axis forward
  EXPECT_LT((m.linear().col(0) + Eigen::Vector3d::UnitY()).norm(), 1e-12);   // image x to the right
  EXPECT_LT((m.linear().col(1) + Eigen::Vector3d::UnitZ()).norm(), 1e-12);   // image y down
  // Positive tilt looks down, positive pan looks left.
  EXPECT_LT(head.r_M_c({0.4, 0.0}).linear().col(2).z(), -0.3);
  EXPECT_GT(head.r_M_c({0.0, 0.4}).linear().col(2).y(), 0.3);
}

TEST(MobilePanTilt, ForwardInverseRoundTrip) {
  const MobilePanTilt head;
  core::Rng rng = core::makeRng(11);
  int checked = 0;
  for (int i = 0; i < 500; ++i) {
    const PanTiltJoints q{core::uniform(rng, -0.6, 1.4), core::uniform(rng, -2.9, 2.9)};
    // Forward: the floor point on the optical axis.
    const Eigen::Isometry3d m = head.r_M_c(q);
    const Eigen::Vector3d c = m.translation(), axis = m.linear().col(2);
    if (axis.z() > -1e-3) continue;
    const Eigen::Vector3d ground = c + (-c.z() / axis.z()) * axis;
    // Inverse, then forward again.
    const auto back = head.pointAt(ground);
    ASSERT_TRUE(back.has_value()) << q.tilt << " " << q.pan;
    EXPECT_NEAR(back->tilt, q.tilt, 1e-9);
    EXPECT_NEAR(back->pan, q.pan, 1e-9);
    ++checked;
  }
  EXPECT_GT(checked, 200);  // axes pointing at the floor (about half of the draws)
}

TEST(MobilePanTilt, ReachesTheGripperZone) {
  // The object in the gripper (about 20 cm ahead of the axle, centre 2.5 cm high) stays in view.
  const MobilePanTilt head;
  for (const double y : {-0.06, 0.0, 0.06}) {
    const auto q = head.pointAt(Eigen::Vector3d(0.2, y, 0.025));
    ASSERT_TRUE(q.has_value()) << y;
    EXPECT_GT(q->tilt, 1.0);
  }
}

TEST(MobilePanTilt, InverseKinematicsPutsFloorPointsOnTheOpticalAxis) {
  const MobilePanTilt head;
  core::Rng rng = core::makeRng(5);
  for (int i = 0; i < 500; ++i) {
    // Floor points ahead within ±60° (the tilt-then-pan head cannot look sideways-down: the
    // sweep plane of the pan contains the lateral horizontal direction, see the header).
    const double r = core::uniform(rng, 0.5, 6.0), bearing = core::uniform(rng, -1.05, 1.05);
    const Eigen::Vector3d p(r * std::cos(bearing), r * std::sin(bearing), core::uniform(rng, 0.0, 0.05));
    const auto q = head.pointAt(p);
    ASSERT_TRUE(q.has_value()) << r << " " << bearing;
    const Eigen::Vector3d p_c = head.r_M_c(*q).inverse() * p;
    EXPECT_GT(p_c.z(), 0.0);
    EXPECT_LT(std::hypot(p_c.x(), p_c.y()) / p_c.z(), 1e-9);  // on the principal point
  }
}

TEST(MobilePanTilt, UnreachablePointsAndBadParameters) {
  const MobilePanTilt head;
  EXPECT_FALSE(head.pointAt(Eigen::Vector3d(0.01, 0.0, 0.41)).has_value());  // inside the head
  EXPECT_FALSE(head.pointAt(Eigen::Vector3d(0.5, 0.0, 3.0)).has_value());    // steeply above: tilt limit
  // A floor point straight to the side: no exact solution, the best pointing is within the
  // limits and better than the home pose.
  const Eigen::Vector3d side(0.0, 2.0, 0.0);
  EXPECT_FALSE(head.pointAt(side).has_value());
  double err = -1.0;
  const PanTiltJoints q = head.pointAtBest(side, &err);
  EXPECT_TRUE(head.withinLimits(q));
  EXPECT_GT(err, 0.0);
  EXPECT_NEAR(err, head.pointingError(q, side), 1e-12);
  EXPECT_LT(err, head.pointingError({0.0, 0.0}, side) - 0.5);
  const Eigen::Vector3d ahead(2.0, 0.5, 0.0);
  EXPECT_NEAR(head.pointingError(head.pointAtBest(ahead), ahead), 0.0, 1e-9);
  MobilePanTiltParams bad;
  bad.l2 = -1.0;
  EXPECT_THROW(MobilePanTilt{bad}, core::InvalidInput);
  EXPECT_THROW(head.pointAt(Eigen::Vector3d(NAN, 0, 0)), core::InvalidInput);
}

TEST(MobilePanTilt, CameraPoseOnTheFloor) {
  const MobilePanTilt head;
  const PanTiltJoints q{0.6, -0.3};
  const Eigen::Isometry3d c_M_w = headCamera_c_M_w(head, q, 1.0, -2.0, 0.7);
  const Eigen::Vector3d centre_w = c_M_w.inverse().translation();
  const Eigen::Vector3d expected = baseOnFloor(1.0, -2.0, 0.7) * head.cameraCenter(q);
  EXPECT_LT((centre_w - expected).norm(), 1e-12);
}

}  // namespace
}  // namespace viewline::robots
