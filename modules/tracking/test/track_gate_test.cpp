#include "viewline/tracking/track_gate.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "viewline/core/error.h"
#include "viewline/core/random.h"
#include "viewline/core/statistics.h"

using namespace viewline;
using tracking::GateDecision;
using tracking::TrackGate;

TEST(TrackGate, ThresholdIsTheChiSquareQuantileOfTheRows) {
  const TrackGate g2(2, {0.99, 3});
  EXPECT_NEAR(g2.threshold(), -2.0 * std::log(0.01), 1e-9);  // chi-square(2): q = -2 ln(1 - p)
  const TrackGate g3(3, {0.999, 3});
  EXPECT_NEAR(g3.threshold(), core::chiSquareQuantile(3.0, 0.999), 1e-12);
}

TEST(TrackGate, StartsAcceptsRejectsAndRestartsAfterNInARow) {
  TrackGate g(2, {0.99, 3});
  const double in = 1.0, out = 100.0;
  EXPECT_EQ(g.decide(0.0, out), GateDecision::Start);  // no track: untested
  EXPECT_EQ(g.decide(0.1, in), GateDecision::Accept);
  EXPECT_EQ(g.decide(0.2, out), GateDecision::Reject);
  EXPECT_EQ(g.decide(0.3, out), GateDecision::Reject);
  EXPECT_EQ(g.rejectedInARow(), 2);
  EXPECT_EQ(g.decide(0.4, out), GateDecision::Restart);
  EXPECT_EQ(g.rejectedInARow(), 0);
  EXPECT_EQ(g.decide(0.5, out), GateDecision::Reject);
  EXPECT_EQ(g.decide(0.6, in), GateDecision::Accept);  // an acceptance ends the run
  EXPECT_EQ(g.rejectedInARow(), 0);
  const auto& c = g.counts();
  EXPECT_EQ(c.starts, 1u);
  EXPECT_EQ(c.accepted, 2u);
  EXPECT_EQ(c.rejected, 3u);
  EXPECT_EQ(c.restarts, 1u);
  EXPECT_EQ(c.total(), 7u);
}

TEST(TrackGate, NanIsRejectedNeverFused) {
  TrackGate g(2, {0.99, 5});
  g.decide(0.0, 0.0);
  EXPECT_EQ(g.decide(0.1, std::numeric_limits<double>::quiet_NaN()), GateDecision::Reject);
}

TEST(TrackGate, ACoastedTrackIsStaleAndTheNextMeasurementStartsANewOne) {
  TrackGate g(2, {0.99, 3, 0.5});
  EXPECT_EQ(g.decide(0.0, 0.0), GateDecision::Start);
  EXPECT_EQ(g.decide(0.2, 100.0), GateDecision::Reject);  // rejections do not refresh the track
  EXPECT_EQ(g.decide(0.5, 1.0), GateDecision::Accept);    // 0.5 s after the last use: still live
  EXPECT_EQ(g.decide(1.01, 100.0), GateDecision::Start);  // 0.51 s: stale
  g.drop();
  EXPECT_FALSE(g.active());
  EXPECT_EQ(g.decide(1.1, 1.0), GateDecision::Start);
}

TEST(TrackGate, RejectionsAreCountedPerSource) {
  TrackGate g(2, {0.99, 2}, 2);
  g.decide(0.0, 0.0, 0);
  EXPECT_EQ(g.decide(0.1, 100.0, 1), GateDecision::Reject);
  EXPECT_EQ(g.decide(0.2, 1.0, 0), GateDecision::Accept);   // source 0 agrees...
  EXPECT_EQ(g.decide(0.3, 100.0, 1), GateDecision::Restart);  // ...source 1's run still counts
  EXPECT_THROW(g.decide(0.4, 1.0, 2), core::InvalidInput);
}

TEST(TrackGate, ARunOfOneSourceIsOutvotedByTwoOtherSourcesThatAgree) {
  TrackGate g(2, {0.99, 2}, 4);  // outvoted_by 2 (default)
  g.decide(0.0, 0.0, 0);
  EXPECT_EQ(g.decide(0.1, 100.0, 3), GateDecision::Reject);  // source 3's run begins
  EXPECT_EQ(g.decide(0.2, 1.0, 0), GateDecision::Accept);    // one other source agrees...
  EXPECT_EQ(g.decide(0.3, 1.0, 1), GateDecision::Accept);    // ...and a second one
  EXPECT_EQ(g.decide(0.4, 100.0, 3), GateDecision::Reject);  // outvoted: the track stays
  EXPECT_EQ(g.counts().outvoted, 1u);
  EXPECT_EQ(g.counts().restarts, 0u);
  EXPECT_EQ(g.decide(0.5, 100.0, 3), GateDecision::Reject);  // still outvoted (the run goes on)
  // Accepts that came before the run do not vote: a new run of source 2 with no agreement since.
  EXPECT_EQ(g.decide(0.6, 100.0, 2), GateDecision::Reject);
  EXPECT_EQ(g.decide(0.7, 100.0, 2), GateDecision::Restart);
  EXPECT_EQ(g.counts().restarts, 1u);
}

TEST(TrackGate, OneAgreeingSourceDoesNotOutvoteAndZeroTurnsOutvotingOff) {
  TrackGate one(2, {0.99, 2}, 4);
  one.decide(0.0, 0.0, 0);
  EXPECT_EQ(one.decide(0.1, 100.0, 3), GateDecision::Reject);
  EXPECT_EQ(one.decide(0.2, 1.0, 0), GateDecision::Accept);  // only one other view agrees
  EXPECT_EQ(one.decide(0.3, 100.0, 3), GateDecision::Restart);
  tracking::TrackGateConfig off{0.99, 2};
  off.outvoted_by = 0;
  TrackGate g(2, off, 4);
  g.decide(0.0, 0.0, 0);
  g.decide(0.1, 100.0, 3);
  g.decide(0.2, 1.0, 0);
  g.decide(0.3, 1.0, 1);
  EXPECT_EQ(g.decide(0.4, 100.0, 3), GateDecision::Restart);
  off.outvoted_by = -1;
  EXPECT_THROW(TrackGate(2, off, 4), core::InvalidInput);
}

TEST(TrackGate, AcceptanceRateOfConsistentInnovationsIsTheGateProbability) {
  // Innovations drawn from N(0, I2) have NIS ~ chi-square(2): the gate accepts a fraction p.
  TrackGate g(2, {0.95, 1000000});
  core::Rng rng = core::makeRng(7);
  g.decide(0.0, 0.0);
  const int n = 40000;
  for (int i = 0; i < n; ++i) {
    const double a = core::gaussian(rng), b = core::gaussian(rng);
    g.decide(1e-3 * (i + 1), a * a + b * b);
  }
  const double rate = static_cast<double>(g.counts().accepted) / n;
  EXPECT_NEAR(rate, 0.95, 4.0 * std::sqrt(0.95 * 0.05 / n));
}

TEST(TrackGate, BadConfigIsRefusedWithItsName) {
  try {
    TrackGate g(2, {1.5, 3});
    FAIL();
  } catch (const core::InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("gate.probability"), std::string::npos);
  }
  EXPECT_THROW(TrackGate(2, {0.99, 0}), core::InvalidInput);
  EXPECT_THROW(TrackGate(2, {0.99, 3, 0.0}), core::InvalidInput);
  EXPECT_THROW(TrackGate(0, {0.99, 3}), core::InvalidInput);
}

TEST(TrackGate, ProbabilityOneTurnsTheTestOffButStillRejectsNaN) {
  TrackGate g(2, {1.0, 2});
  EXPECT_TRUE(std::isinf(g.threshold()));
  EXPECT_EQ(g.decide(0.0, 0.0), GateDecision::Start);
  EXPECT_EQ(g.decide(0.1, 1e12), GateDecision::Accept);
  EXPECT_EQ(g.decide(0.2, std::numeric_limits<double>::quiet_NaN()), GateDecision::Reject);
  EXPECT_THROW(TrackGate(2, {1.0 + 1e-9, 2}), core::InvalidInput);
}
