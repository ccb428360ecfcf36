#include "viewline/tracking/track_gate.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>

#include "viewline/core/error.h"
#include "viewline/core/statistics.h"

namespace viewline::tracking {

const char* toString(GateDecision d) {
  switch (d) {
    case GateDecision::Start: return "start";
    case GateDecision::Accept: return "accept";
    case GateDecision::Reject: return "reject";
    case GateDecision::Restart: return "restart";
  }
  return "?";
}

void TrackGateConfig::validate(const char* what) const {
  const std::string w = what;
  if (!(probability > 0.0 && probability <= 1.0))
    throw core::InvalidInput(w + ".probability: expected in (0, 1] (1: no test), got " + std::to_string(probability));
  if (restart_after < 1) throw core::InvalidInput(w + ".restart_after: expected >= 1, got " + std::to_string(restart_after));
  if (!(max_coast_s > 0.0)) throw core::InvalidInput(w + ".max_coast_s: expected > 0 (inf: no limit)");
  if (outvoted_by < 0) throw core::InvalidInput(w + ".outvoted_by: expected >= 0 (0: off), got " + std::to_string(outvoted_by));
}

TrackGate::TrackGate(Eigen::Index dof, TrackGateConfig config, std::size_t sources) : config_(config) {
  config_.validate();
  if (dof < 1) throw core::InvalidInput("TrackGate: dof must be >= 1");
  if (sources < 1) throw core::InvalidInput("TrackGate: sources must be >= 1");
  threshold_ = config_.probability < 1.0 ? core::chiSquareQuantile(static_cast<double>(dof), config_.probability)
                                         : std::numeric_limits<double>::infinity();
  rejected_.assign(sources, 0);
  run_start_.assign(sources, 0);
  last_accept_.assign(sources, 0);
}

void TrackGate::begin(double t) {
  active_ = true;
  last_used_t_ = t;
  std::fill(rejected_.begin(), rejected_.end(), 0);
  std::fill(last_accept_.begin(), last_accept_.end(), 0);
}

GateDecision TrackGate::decide(double t, double nis, std::size_t source) {
  if (source >= rejected_.size()) {
    std::ostringstream s;
    s << "TrackGate::decide: source " << source << " (expected < " << rejected_.size() << ")";
    throw core::InvalidInput(s.str());
  }
  if (!active_ || t - last_used_t_ > config_.max_coast_s) {
    begin(t);
    ++counts_.starts;
    return GateDecision::Start;
  }
  const std::uint64_t n = ++decisions_;
  if (nis <= threshold_) {
    rejected_[source] = 0;
    last_accept_[source] = n;
    last_used_t_ = t;
    ++counts_.accepted;
    return GateDecision::Accept;
  }
  if (rejected_[source]++ == 0) run_start_[source] = n;
  if (rejected_[source] >= config_.restart_after) {
    if (config_.outvoted_by > 0) {
      // Majority of views: other sources that agreed with the track while this one disagreed.
      int agreeing = 0;
      for (std::size_t s = 0; s < last_accept_.size(); ++s)
        agreeing += s != source && last_accept_[s] > run_start_[source];
      if (agreeing >= config_.outvoted_by) {
        ++counts_.rejected;
        ++counts_.outvoted;
        return GateDecision::Reject;
      }
    }
    begin(t);
    ++counts_.restarts;
    return GateDecision::Restart;
  }
  ++counts_.rejected;
  return GateDecision::Reject;
}

void TrackGate::drop() {
  active_ = false;
  std::fill(rejected_.begin(), rejected_.end(), 0);
}

int TrackGate::rejectedInARow() const { return *std::max_element(rejected_.begin(), rejected_.end()); }

}  // namespace viewline::tracking
