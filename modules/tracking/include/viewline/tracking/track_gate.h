#pragma once
// The gate and life cycle every track shares: a chi-square test on the update's own NIS,
// a restart after N rejections in a row, and a coasting limit.
//
// For a consistent filter the normalised innovation squared NIS = dᵀ S⁻¹ d of an m-row update is
// chi-square with m degrees of freedom (Bar-Shalom, Li, Kirubarajan, "Estimation with
// Applications to Tracking and Navigation", 2001, §5.4), so accepting NIS <= χ²_m(p) keeps a
// fraction p of good measurements. A run of rejections means the track, not the measurement, is
// wrong (it was started from an outlier, or the target manoeuvred beyond the model): after
// `restart_after` of them in a row the track restarts from the current measurement. A track that
// has accepted nothing for longer than `max_coast_s` is stale: the next measurement starts a new
// one without being tested against it.
//
//   tracking::TrackGate gate(2, {0.9999, 3});
//   const auto rep = filter.innovation(z);                  // estimation::UpdateReport-like
//   switch (gate.decide(t, rep.nis)) {
//     case GateDecision::Start: case GateDecision::Restart: filter.reset(t, z); break;
//     case GateDecision::Accept: filter.update(z); break;
//     case GateDecision::Reject: break;                     // coast on the prediction
//   }
//
// Rejections may be counted per source (camera): a track started from an outlier of camera A
// keeps agreeing with A while B disagrees, so the restart looks at the longest run of any source.

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

namespace viewline::tracking {

/// What the gate decided for one measurement.
enum class GateDecision : int {
  Start = 0,    ///< no (live) track: the measurement starts one, untested
  Accept = 1,   ///< NIS within the gate: fuse it
  Reject = 2,   ///< NIS outside the gate: do not fuse; the track coasts
  Restart = 3,  ///< the restart_after-th rejection in a row: restart the track from it
};
/// Lower-case name of a decision ("start", "accept", "reject", "restart").
const char* toString(GateDecision d);
/// Start, Accept and Restart use the measurement; Reject does not.
inline bool uses(GateDecision d) { return d != GateDecision::Reject; }

/// Configuration of a track's chi-square gate, restart and coasting life cycle.
struct TrackGateConfig {
  /// Chi-square acceptance probability, in (0, 1]; 1 turns the test off (every measurement with a
  /// finite NIS is accepted, so the track never restarts) for filters shipped without a gate.
  double probability = 0.999;
  int restart_after = 3;       ///< rejections in a row (of one source) that restart the track, >= 1
  double max_coast_s = std::numeric_limits<double>::infinity();  ///< > 0; inf: a track never goes stale
  /// A source's run of rejections does not restart the track while at least this many OTHER sources
  /// had a measurement accepted during the run (0: never outvoted). Two other views that agree with
  /// the track triangulate it: the one that disagrees is biased (an unregistered camera), not the
  /// track. With two sources or fewer the default changes nothing.
  int outvoted_by = 2;
  void validate(const char* what = "gate") const;  ///< throws core::InvalidInput naming `what`
};

/// How many measurements each decision took.
struct GateCounts {
  std::uint64_t starts = 0,    ///< Start decisions
                accepted = 0,  ///< Accept decisions
                rejected = 0,  ///< Reject decisions
                restarts = 0,  ///< Restart decisions
                outvoted = 0;  ///< Reject decisions that would have restarted the track but were outvoted
  /// Every decision counted.
  std::uint64_t total() const { return starts + accepted + rejected + restarts; }
};

/// The chi-square gate + restart + coasting life cycle every track shares: decides Start, Accept, Reject or
/// Restart per measurement.
class TrackGate {
public:
  /// `dof`: rows of the update (the NIS's degrees of freedom); `sources`: how many independent
  /// sources count their rejections apart (1: one counter). Throws core::InvalidInput.
  TrackGate(Eigen::Index dof, TrackGateConfig config, std::size_t sources = 1);

  /// The decision for a measurement at time t whose innovation has NIS `nis` (ignored when
  /// there is no live track). A NaN NIS is rejected.
  GateDecision decide(double t, double nis, std::size_t source = 0);

  /// Forget the track: the next measurement starts a new one.
  void drop();
  /// True while a track is live (started, not dropped, not stale).
  bool active() const { return active_; }

  /// NIS threshold χ²(dof, probability).
  double threshold() const { return threshold_; }
  /// The configuration in use.
  const TrackGateConfig& config() const { return config_; }
  /// The longest current run of rejections over the sources.
  int rejectedInARow() const;
  /// Time of the last measurement the track used (Start, Accept or Restart), s.
  double lastUsedTime() const { return last_used_t_; }
  /// Decisions taken since construction.
  const GateCounts& counts() const { return counts_; }

private:
  void begin(double t);
  TrackGateConfig config_;
  double threshold_;
  std::vector<int> rejected_;
  std::vector<std::uint64_t> run_start_;    // per source: the decision that began its run of rejections
  std::vector<std::uint64_t> last_accept_;  // per source: its last accepted decision in this track (0: none)
  std::uint64_t decisions_ = 0;             // decisions since construction (1, 2, ...)
  bool active_ = false;
  double last_used_t_ = 0.0;
  GateCounts counts_;
};

}  // namespace viewline::tracking
