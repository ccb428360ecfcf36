// The planar target filter on tracking::TrackGate decides as its own hand-written gate did (NIS > χ²₂(p):
// reject; reinit_after rejections in a row: re-initialise): the decisions below were recorded from the
// filter before it used TrackGate, on seeded sequences with outliers, bursts and gaps, for every model.
// Seed 2, config 7 (the constant-speed legs with the soft corner mixture) was recorded again when that
// mixture came to weigh the jump times up to the last measurement: its estimate moved, so near one corner a
// declared jump became a rejection one sample later (the filter, not the gate, changed).
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

struct FilterRun {
  std::string code;
  tracking::GateCounts counts;  ///< from the decisions the filter reported
};

FilterRun runFilter(std::uint64_t seed, int which) {
  tracking::PlanarTargetFilter f(gateConfig<tracking::TargetFilterConfig, tracking::TargetModel>(which));
  FilterRun run;
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
    if ((c == '-' || c == 'r') && f.config().model != tracking::TargetModel::WaypointParticles) {
      EXPECT_GT(u.nis, f.gateThreshold());
    }
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
    {{
        "s1a28-2r1-1a11-1a29-1a6-1a11.58s1a67.12-2r1a43-1a22-2r1a2.62s1a49-2a1-1a24-1a26.61s1a10-1a54-2r1"
        "a36-2r1-2r1a14-1a40-1a42-1a1-1a1-2a39-1a31-1a13-2a4-1a6-2r1-2a49",
        "s1a28-2r1-1a11-1a9j1a8j1a5j1a11-1a1j1a8j1.58s1a35j2a9j1a13j2a5.12j1a6j1a9j1a15j1a9j1a2-1a12j1a13"
        "j1.62s1a20j1a19j1a8-2a1-1a2j1a5j1a15j1a14j1a6j1a4.61s1a10-1a5j1-1a27j1a19j1a4-1a6j1a5j1a13j1a6-2"
        "r1-2r1a14-1a5j1a8j1a15j1a9-1a5j1a11j1a16j1a7j1a11j1a5j1a7j1a10j1a4j1a2-1a11-1a17j1a1-1a16j1a6j1a"
        "2-2r1-2a19j1a17j1a8j1a2",
        "s1a28-2r1-1a11-1a10j1a9j1a8j1a12j1a5.58s1a38j2a12j1a13j1.12j1a3j1a13j1a16j1a8j1a1-1a14j1a12.62s1"
        "a20j1a24j1a3-2a1-1a2j1a5j1a17j1a19j1a4.61s1a10-1a5j1-1a27j1a19j1a4-1a9j1a4j1a14j1a3-2r1-2r1a14-1"
        "a5j1a8j1a21j1a3-1a6j1a12j1a16j1a13j1a4j1a15j1a14j1-1a11-1a1j1a17-1a23j1a2-2r1-2a19j1a19j1a9",
        "s1a28-2r1-1a11-1a29-1j1a17.58s1a67.12-1a45-1a20-1a6.62s1a49-2a1-1a2j1a5j1a15-1a26.61s1a10-1a54-1"
        "a4-1a33-2r1-2r1a14-1a5j1a34-1a10j1a29-1a46-1a31-1a1-1a24-2r1-2a43j1a5",
        "s1a28-2r1-1a11-1a48.58s1a67.12a1-1a44-1a27.62s1a49-2a1-1a24-1a26.61s1a10-1a54-2a37-2r1-2r1a14-1a"
        "40-1a87-1a31-1a26-2r1-2a49",
        "s1a28-2r1-2r1a9-1a29-1a18.58s1a67.12-1a45-1a19j1a7.62s1a49-2a1-1a4j1a6j1a12-1a26.61s1a10-1a54-1a"
        "4-1a33-2r1-2r1a14-1a40-1a40-2a45-1a31-1a1j1a24-2r1-2r1a48",
        "s1a28-2r1-2r1a9-1a29-1a3j1a14.58s1a67.12-2r1a43-1a19j1a7.62s1a49-2a1-1a2j1a21-1a26.61s1a10-1a54-"
        "2r1a36-2r1-2r1a14-1a25j1a14-1a40-2r1a44-1a31-1a5-1a20-2r1-2r1a48",
        "s1a28-2r1-2r1a9-1a29-1a3j1a14.58s1a67.12-2r1a43-1a19j1a7.62s1a49-2a1-1a2j1a21-1a26.61s1a10-1a54-"
        "2r1a36-2r1-2r1a14-1a15j1a24-1a40-2r1a44-1a31-1a5-1a20-2r1-2r1a48",
        "s1a29r1a1r1a27r1a32.58s1a67.12a74.62s1a50r1a2r1a50.61s1a105r1a2r1a204r1a1r1a1r1a48",
    }},
    {{
        "s1a32-2r1-2a22-2r1-1a35.17-2r1a55-1a8-2r1-1a58-1a2-1a1-1a12-1a60-1a3-1a33-2r1a6-1a73-1a28-2r1-2r"
        "1a49-2r1-2r1a6-1a1-2r1a42-1a5-1a6-2r1-1a31-1a3-1a20-2a21-1a3.67s1a5-1a18-1a20.24a9-1a23-1a4-1a36",
        "s1a23j1a8-2r1-2a14j1a7-2r1-1a10j1a24.17j1-1a7j1a1j1a17j1a15j1a9j1a2-1a8-2r1-1a21j1a18j1a15j2a17j"
        "1a16j1a3j1a16j1a1j1a13j1a6j1a6j1a2-1a10j1a9j1a7-2a7-1a5j1a6j1a8j1a3j1a10j1a5j1a8j1a9j1a4-1a6-1a5"
        "j1a5j1a10j1a5-2r1-2r1a33j3a13-2r1-2r1a6-1a1-2r1a34j1a7j1a5-1a5j1-2a2-2r1a25j1a25j1a1j1a9j1a13j1a"
        "2.67s1a5-1a18-1a2j1a9j1a1-1a3j1a1.24a5j1a3-1a9j1a18j1a17j1a2j1-1a14",
        "s1a25j1a6-2r1-2a14j1a7-2r1-1a10j1a24.17j1-1a10j1a2j1a16j1a12j1a10j1a1-1a8-2r1-1a22j1a19j1a15j2a2"
        "0j1a13j1a6j1a14j1a19j1a9j1a1j1a6j1a3j1a2-1a5j1a7j1a21j1a17j1a17j1a14j1a8-1a4j1a6j1a16-2r1-2r1a34"
        "j2a13-2r1-2r1a6-1a1-2r1a36j1a6j1a4-1a5j1-2a2-2r1a25j1a28j1a22j1a2.67s1a5-1a18-1a5j1a9j1a4.24j1a8"
        "-1a1j1a18j1a20j1a8-1a12j2",
        "s1a32-2r1-2a22-2r1-1a10j1a24.17-1a1-2r1a62-2r1-1a58-1a2-1a55-1a4-1a52-2r1a6-1a73-1a5j1a5j1a16-2r"
        "1-2r1a35-1a12-2r1-2r1a7-1a1-2r1a42-1a5-1a6-2a2-1a1j1a5j1a22-1a51.67s1a5-1a18-1a20.24a9-1a12j1a37"
        "-1a14",
        "s1a32-2r1-2a22-2r1-1a35.17a2-1a64-2r1-1a175-1a8-1a66-1a6-1a28-2r1-2r1a49-2r1-2r1a6-1a1-2r1a42-1a"
        "5-1a6-2r1-1a83.67s1a5-1a18-1a20.24a9-1a50-1a14",
        "s1a32-2r1-2a22-2r1-1a14j1a20.17-2r1a35j1a19-1a8-2r1-1a56-1a60-1a2j1a54-2r1a6-1a73-1a8j1a3-1a2j1a"
        "12-2r1-2r1a40j1a8-2r1-2r1a6-1a1-2r1a42-1a5-1a6-2a33-1a47-1a3.67s1a5-1a18-1a20.24a9-1a14j1a50",
        "s1a32-2r1-2a22-2r1-1a10j1a24.17-2r1a35j1a28-2r1-1a56-1a1-1a1j1a62j1a51-2r1a6-1a73-1a12-1a15-2r1-"
        "2r1a40j1a8-2r1-2r1a6-1a1-2r1a42-1a5-1a6-2r1-2a30-1j1a46-1a3.67s1a5-1a18-1a20.24a9-1a19-1a45",
        "s1a32-2r1-2a22-2r1-1a10j1a24.17-2r1a35j1a28-2r1-1a56-1a1-1a1j1a62j1a51-2r1a6-1a73-1a12-1a15-2r1-2r"
        "1a43j1a5-2r1-2r1a6-1a1-2r1a42-1a5-1a6-2r1-2a30-1j1a46-1a3.67s1a5-1a18-1a20.24a9-1a19-1a45",
        "s1a33r1a1r1a24r1a3r1a33.17a24r1a43r1a1r1a1r1a129r1a156r1a1r1a52r1a1r1a3r1a7r1a1r1a55r1a1r1a57r1a"
        "25.67s1a45.24a75",
    }},
    {{
        "s1a95-1a70-1a2-1a2-1a85-1a8-1a7-1a5-1a42-1a48-1a9-1a2-1a1-2r1a27-1a1-1a6-1a9-1a16-2r1a25-1a17-1a"
        "24-1a6-1a1-1a1-1a5-2r1a72-1a3-2a20-1a22-1a18-1a17-1a1-1a109-1a2.32-2r1a20-1a25",
        "s1a37j1a10j1a24j1a7j1a13j1a17j1a10j1a13j1a3j1a17j1a5-1a2-2a1-1a5j1a18j1a13j1a14j1a13j1a2-1j1a27j"
        "2a8j1a3j1a11j1a3j1a10j1a8j1a1-1a5j1a9j1a2j1a11j1a8j1a1-1a7j1a7j1a1j1a15j1a2j1a7j1a4j1a1-1a1-1a6-"
        "1a2j1a2j1a3-1a5j1a11j1a5j1a11j1a8-1a3j1a10j1a2-1j1a13j1a9-1a3j1a11j1a1-1a5j1a16j1a6j1a10j1a7j1a8"
        "j1a4j1a10j1a14j1a1j1a8-1a12j1a8j1a6j1a14j1a3j1a11-1a6j1a9j1a7j1a4j1a9j1a7j1a12j1a8j1a9j1a12j1a9j"
        "1a11.32j1a4j1a6j1a19j1a14j1a1",
        "s1a40j1a8j1a27j1a5j1a16j1a17j1a4j1a11j1a12j1a6j1a10-1a2-2a1-1a5j1a20j1a21j1a9j1a8j1a2-1a5j1a25j1"
        "a12j1a4j1a19j1a9j1-1a10j1a11j1a9j1a8-1j1a5j2a20j1a16j1a5-1a5j1-1a4j1a6-1a9j1a25j1a5j1a18j1a1-1j1"
        "a20j2a1-1a4j1a9j1a2-1a15j1a15j1a19j1a2j1a22j1a13j1a16j1a7j1a6j1a18j1a14j1a1-1a15j1a9j1a12j1a13j1"
        "a8j1a11-1j1a23j1a5j1a4j1a4.32j1a10j1a3j1a7j1a25",
        "s1a87-2r1a76-1a2-2a1-1a27j1a39j1a2-1a14-1a8-1a2-1a1-2r1a47-1a50-1a44-1a1-1a3j1-1a4j1a6-1a13j1a30"
        "-2a2-1a1-1a4-1a5-2a6j1a17-1a5j1a5j1a5-1a69j1a29-1a22-1a3-1a7j1a24-1a34-1j1a34j1a2-1a40.32-2r1a20"
        "-1a25",
        "s1a166-1a2-1a2-1a85-1a65-1a93-1a1-1a16-1a9-2a33-1a42-1a17-1a159-1a114.32a49",
        "s1a87-2a77-1a2-1a2-1a52j1a8j1a8-1a14-1a5-1a2-1a54-1a50-1a44-1a6-1j1a10-1a2j1a6-2a1-1a29-1a44-1a6"
        "-1a1-1a8-1a68j1a30-1a22-1a3-1a32-1a1-1a3-1a4-1a56-1a2-1a36-1a3-2a1.32-1a48",
        "s1a87-2r1a76-1a2-1a1j1-1a3j1a58j1a7-1a14-1a1-1a3-1a2-2a55-1a48-2r1a42-1a1-1a6-1a6-1a2-1a9-2a1-2a"
        "28-2a18-1a24-1a6-1a1-2r1a6-1a69-1j1a28-1a22-1a3-1a32-1a1-1a3-1j1a60-1a2-2a1-1a37-2a1.32a49",
        "s1a87-2r1a76-1a2-1a1j1-1a3j1a58j1a7-1a14-1a5-1a2-1a54-1a1-1a48-2r1a42-1a1-1a6-1a6-1a1j1-1a9-2a1-"
        "2a28-2r1a17-1a24-1a6-1a1-2a7-1a69-1a1j1a27-1a22-1a3-1a32-1a1-1a2j1a62-1a2-2a39-2j1.32a49",
        "s1a493r1a324.32a49",
    }},
}};
}  // namespace

TEST(PlanarTargetFilter, GateDecisionsAreThoseOfTheFilterBeforeTrackGate) {
  bool rejected = false, restarted = false;
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    for (int w = 0; w < tracking::planar_test::kGateConfigs; ++w) {
      const FilterRun run = runFilter(seed, w);
      EXPECT_EQ(runLengths(run.code), kRecorded[seed - 1][static_cast<std::size_t>(w)]) << "seed " << seed << " config " << w;
      rejected = rejected || run.counts.rejected > 0;
      restarted = restarted || run.counts.restarts > 0;
    }
  }
  EXPECT_TRUE(rejected && restarted);  // the sequences exercise every decision
}

TEST(WaypointParticleFilter, RestartsAsBeforeTrackGate) {
  // Restarts (reinit_after = 2 measurements in a row that no particle explains) recorded before the
  // particle filter counted them with TrackGate.
  const std::array<std::size_t, 3> recorded{11, 13, 4};
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    tracking::WaypointParticleConfig c;
    c.particles = 500;
    c.region_size = Eigen::Vector2d(0.80, 0.43);
    c.min_leg = 0.1;
    c.speed_min = 0.1;
    c.speed_max = 0.2;
    c.reinit_after = 2;
    c.seed = seed;
    tracking::WaypointParticleFilter f(c);
    for (const auto& s : tracking::planar_test::gateSequence(seed)) {
      if (s.detected)
        f.update(s.t, s.z, s.R);
      else
        f.propagateTo(s.t);
    }
    EXPECT_EQ(f.reinitialisations(), recorded[seed - 1]) << seed;
    EXPECT_EQ(f.gateCounts().restarts, recorded[seed - 1]) << seed;
    EXPECT_EQ(f.gateCounts().starts, 1u) << seed;
  }
}
