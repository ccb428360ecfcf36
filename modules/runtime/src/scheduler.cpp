#include "viewline/runtime/scheduler.h"

#include <cmath>
#include <sstream>
#include <thread>

#include "viewline/core/error.h"

namespace viewline::runtime {

namespace {
void requireTime(double t, double now, const char* what) {
  if (!std::isfinite(t)) {
    std::ostringstream s;
    s << "Scheduler::" << what << ": time " << t << " (expected finite)";
    throw core::InvalidInput(s.str());
  }
  if (t < now) {
    std::ostringstream s;
    s.precision(17);
    s << "Scheduler::" << what << ": time " << t << " is before now (" << now << ")";
    throw core::InvalidInput(s.str());
  }
}
}  // namespace

Scheduler::Scheduler(double t0) : now_(t0) {
  if (!std::isfinite(t0)) throw core::InvalidInput("Scheduler: start time must be finite");
}

void Scheduler::push(double t, int priority, EventId id) { queue_.push({t, priority, next_order_++, id}); }

EventId Scheduler::at(double t, int priority, Action action) {
  requireTime(t, now_, "at");
  if (!action) throw core::InvalidInput("Scheduler::at: empty action");
  const EventId id = next_id_++;
  entries_.emplace(id, Entry{std::move(action), 0.0, 0.0});
  push(t, priority, id);
  return id;
}

EventId Scheduler::every(double t_first, double period, int priority, Action action, double until) {
  requireTime(t_first, now_, "every");
  if (!(period > 0.0) || !std::isfinite(period)) {
    std::ostringstream s;
    s << "Scheduler::every: period " << period << " s (expected > 0 and finite)";
    throw core::InvalidInput(s.str());
  }
  if (std::isnan(until)) throw core::InvalidInput("Scheduler::every: 'until' is NaN");
  if (!action) throw core::InvalidInput("Scheduler::every: empty action");
  const EventId id = next_id_++;
  if (t_first > until) return id;  // never runs
  entries_.emplace(id, Entry{std::move(action), period, until});
  push(t_first, priority, id);
  return id;
}

void Scheduler::cancel(EventId id) {
  if (id != 0 && id == running_) {
    cancel_running_ = true;  // erased when its action returns (it is executing now)
    return;
  }
  entries_.erase(id);
}

std::optional<double> Scheduler::nextTime() const {
  // Cancelled events stay queued until they reach the top; skip them without mutating (rare).
  if (entries_.empty()) return std::nullopt;
  auto copy = queue_;
  while (!copy.empty() && entries_.count(copy.top().id) == 0) copy.pop();
  if (copy.empty()) return std::nullopt;
  return copy.top().t;
}

void Scheduler::setPacing(Pacing pacing) {
  if (!(pacing.factor >= 0.0) || !std::isfinite(pacing.factor))
    throw core::InvalidInput("Scheduler: pacing factor must be >= 0 and finite (0: as fast as possible)");
  pacing_ = pacing;
  pace_started_ = false;
}

void Scheduler::waitForWallClock(double t) {
  if (!pacing_.paced()) return;
  const auto wall_now = std::chrono::steady_clock::now();
  if (!pace_started_) {
    pace_started_ = true;
    pace_t0_ = t;
    pace_wall0_ = wall_now;
    return;
  }
  const auto due = pace_wall0_ + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                     std::chrono::duration<double>((t - pace_t0_) / pacing_.factor));
  if (due > wall_now) std::this_thread::sleep_until(due);
}

void Scheduler::runOne() {
  const Event e = queue_.top();
  queue_.pop();
  auto it = entries_.find(e.id);
  if (it == entries_.end()) return;  // cancelled
  waitForWallClock(e.t);
  now_ = e.t;
  ++events_run_;
  Entry& entry = it->second;  // element references survive rehashing (new events may be added)
  const bool again = entry.period > 0.0 && e.t + entry.period <= entry.until;
  if (again) push(e.t + entry.period, e.priority, e.id);  // before running: the action may cancel it
  running_ = e.id;
  cancel_running_ = !again;
  entry.action(e.t);
  running_ = 0;
  if (cancel_running_) entries_.erase(e.id);
}

std::size_t Scheduler::runUntil(double t_end) {
  if (std::isnan(t_end)) throw core::InvalidInput("Scheduler::runUntil: end time is NaN");
  std::size_t n = 0;
  while (!stopRequested() && !queue_.empty() && queue_.top().t <= t_end) {
    const bool live = entries_.count(queue_.top().id) != 0;
    runOne();
    if (live) ++n;
  }
  if (!stopRequested() && t_end > now_ && std::isfinite(t_end)) now_ = t_end;
  return n;
}

bool Scheduler::step() {
  while (!stopRequested() && !queue_.empty()) {
    if (entries_.count(queue_.top().id) == 0) {
      queue_.pop();
      continue;
    }
    runOne();
    return true;
  }
  return false;
}

}  // namespace viewline::runtime
