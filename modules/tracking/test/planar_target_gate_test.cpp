// The planar target filter on tracking::TrackGate decides as its own hand-written gate did (NIS > χ²₂(p):
// reject; reinit_after rejections in a row: re-initialise): the decisions below were recorded from the
// filter before it used TrackGate, on seeded sequences with outliers, bursts and gaps, for every model.
#include <gtest/gtest.h>

#include <array>
#include <string>

#include "planar_target_gate_configs.h"
#include "planar_target_sequence.h"
#include "viewline/tracking/planar_target/filter.h"
#include "viewline/tracking/planar_target/waypoint_particles.h"

using namespace viewline;
using tracking::planar_test::gateConfig;

namespace {
// One character per sample: '.' not detected, 's' (re)started by the caller (lost for more than 1.5 s,
// the controller's reacquisition), 'a' accepted, 'j' accepted with a jump detected, '-' rejected,
// 'r' re-initialised by the gate. Run-length encoded: "a57" is 57 'a'.
std::string runLengths(const std::string& code) {
  std::string out;
  for (std::size_t i = 0; i < code.size();) {
    std::size_t j = i;
    while (j < code.size() && code[j] == code[i]) ++j;
    out += code[i] + std::to_string(j - i);
    i = j;
  }
  return out;
}

struct Run {
  std::string code;
  tracking::GateCounts counts;  ///< from the decisions the filter reported
};

Run runFilter(std::uint64_t seed, int which) {
  tracking::PlanarTargetFilter f(gateConfig<tracking::TargetFilterConfig, tracking::TargetModel>(which));
  Run run;
  double last_accepted = -1e300;
  for (const auto& s : tracking::planar_test::gateSequence(seed)) {
    if (!s.detected) {
      run.code += '.';
      continue;
    }
    if (s.t - last_accepted > 1.5 || !f.initialized()) {
      f.reset(s.t, s.z, s.R);
      run.code += 's';
      ++run.counts.starts;
      last_accepted = s.t;
      continue;
    }
    const auto u = f.update(s.t, s.z, s.R);
    EXPECT_TRUE(u.decision.has_value());
    const char c = u.reinitialized ? 'r' : (!u.accepted ? '-' : (u.jump ? 'j' : 'a'));
    run.code += c;
    if (u.accepted) last_accepted = s.t;
    switch (c) {
      case 'r': ++run.counts.restarts; EXPECT_EQ(*u.decision, tracking::GateDecision::Restart); break;
      case '-': ++run.counts.rejected; EXPECT_EQ(*u.decision, tracking::GateDecision::Reject); break;
      default: ++run.counts.accepted; EXPECT_EQ(*u.decision, tracking::GateDecision::Accept); break;
    }
    if (c == '-' || c == 'r') EXPECT_TRUE(u.nis > f.gateThreshold() || f.config().model == tracking::TargetModel::WaypointParticles);
  }
  const tracking::GateCounts& n = f.gateCounts();
  EXPECT_EQ(n.starts, run.counts.starts);
  EXPECT_EQ(n.accepted, run.counts.accepted);
  EXPECT_EQ(n.rejected, run.counts.rejected);
  EXPECT_EQ(n.restarts, run.counts.restarts);
  return run;
}

// Recorded from the filter before the move (seeds 1..3, gateConfig 0..8).
const std::array<std::array<const char*, tracking::planar_test::kGateConfigs>, 3> kRecorded = {{
    // RECORDED
}};
}  // namespace

TEST(PlanarTargetFilter, GateDecisionsAreThoseOfTheFilterBeforeTrackGate) {
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    for (int w = 0; w < tracking::planar_test::kGateConfigs; ++w) {
      const Run run = runFilter(seed, w);
      EXPECT_EQ(runLengths(run.code), kRecorded[seed - 1][static_cast<std::size_t>(w)]) << "seed " << seed << " config " << w;
    }
  }
}
