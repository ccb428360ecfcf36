#pragma once
// One clock for a scenario: a discrete-event scheduler.
//
// Every timed thing a scenario does (a camera capture, a control period, a delayed delivery, a
// physics step) is an event in one queue, ordered by
//
//     (time, priority, order of scheduling)
//
// and run by runUntil(t). Priorities break ties between events at the same simulated time; the
// insertion order breaks the remaining ties, so a run is a deterministic function of its inputs
// (Drake's Simulator plays the same role for its systems: one object advances time, the systems
// hold no clock of their own).
//
// Pacing does not change what runs or in which order, only when: with a factor f > 0 the
// scheduler waits before an event until the wall clock has advanced (t_event − t_start) / f since
// the start of the paced run ("--realtime 20" runs 20 simulated seconds per wall second); with 0
// (the default) it runs as fast as it can. A live camera needs the paced mode.
//
//   runtime::Scheduler sched;
//   sched.every(0.0, 0.001, Priority::Control, [&](double t) { robot.command(planner.setpoint(t)); });
//   sched.at(0.25, Priority::Capture, [&](double t) { ... });
//   sched.runUntil(3.0);

#include <chrono>
#include <cstdint>
#include <functional>
#include <limits>
#include <optional>
#include <queue>
#include <unordered_map>
#include <vector>

#include "viewline/core/interrupt.h"

namespace viewline::runtime {

/// Tie-breaking ranks at equal simulated time (smaller runs first). Scenarios may use any int;
/// these name the usual order: the plant is advanced, deliveries reach their consumer, the
/// controller runs, then a frame is captured and processed.
namespace priority {
/// Plant and simulated-world steps run first.
inline constexpr int Physics = 0;
/// Delayed deliveries (DelayLine) reach their consumer.
inline constexpr int Delivery = 10;
/// Controllers and planners run on what was delivered.
inline constexpr int Control = 20;
/// Frames are captured and processed.
inline constexpr int Capture = 30;
/// Telemetry sampling runs last, on the settled state.
inline constexpr int Telemetry = 40;
}  // namespace priority

/// Identifier of a scheduled event (for Scheduler::cancel()).
using EventId = std::uint64_t;

/// How a run relates to the wall clock.
struct Pacing {
  /// Simulated seconds per wall-clock second; 0 = as fast as possible.
  double factor = 0.0;
  /// True when the run is paced to the wall clock (factor > 0).
  bool paced() const { return factor > 0.0; }
};

/// Discrete-event scheduler: the one clock of a scenario, events ordered by (time, priority, order of scheduling).
class Scheduler {
public:
  /// What an event runs, called with the event's time t (s).
  using Action = std::function<void(double t)>;

  /// Starts the clock at t0 (s). Throws core::InvalidInput for a non-finite t0.
  explicit Scheduler(double t0 = 0.0);

  /// One event at time t (>= now(), finite). Returns its id (for cancel()).
  EventId at(double t, int priority, Action action);

  /// A periodic event: first at t_first, then every `period` s. The next time is the previous
  /// one plus the period, accumulated in double precision exactly as a hand-written
  /// `t += period` loop does, so a loop moved onto the scheduler keeps its time stamps bit for
  /// bit. `until` (inclusive) ends it. Throws for period <= 0 or non-finite times.
  EventId every(double t_first, double period, int priority, Action action,
                double until = std::numeric_limits<double>::infinity());

  /// Removes a pending event (a periodic one stops). Unknown or already-run ids are ignored.
  void cancel(EventId id);

  /// Runs every event with time <= t_end in order (events scheduled while running included);
  /// afterwards now() == max(now(), t_end). Returns the number of events run.
  std::size_t runUntil(double t_end);

  /// Runs the next event only (none pending: returns false).
  bool step();

  /// Time of the next pending event, if any.
  std::optional<double> nextTime() const;

  /// The current simulated time: the time of the event running, or of the last runUntil().
  double now() const { return now_; }

  /// Events still to run (a periodic event counts once).
  std::size_t pending() const { return entries_.size(); }
  /// Number of events run so far.
  std::uint64_t eventsRun() const { return events_run_; }

  /// Wall-clock pacing from now on (the paced run starts at the next event run).
  void setPacing(Pacing pacing);
  /// The pacing in use.
  Pacing pacing() const { return pacing_; }

  /// Asks runUntil()/step() to return before the next event (e.g. a display's quit key);
  /// stopRequested() stays true until clearStop().
  void requestStop() { stop_ = true; }
  /// requestStop() was called, or a signal asked the process to stop (core::interruptRequested():
  /// Ctrl-C / SIGTERM, recorded by the apps' handler), so every scheduler of the process ends its run.
  bool stopRequested() const { return stop_ || core::interruptRequested(); }
  /// Forgets requestStop() (not a signal's request, which belongs to the process).
  void clearStop() { stop_ = false; }

private:
  struct Event {
    double t;
    int priority;
    std::uint64_t order;
    EventId id;
  };
  struct Later {
    bool operator()(const Event& a, const Event& b) const {
      if (a.t != b.t) return a.t > b.t;
      if (a.priority != b.priority) return a.priority > b.priority;
      return a.order > b.order;
    }
  };
  struct Entry {
    Action action;
    double period = 0.0;  // > 0: periodic
    double until = 0.0;
  };

  void push(double t, int priority, EventId id);
  void runOne();
  void waitForWallClock(double t);

  std::priority_queue<Event, std::vector<Event>, Later> queue_;
  std::unordered_map<EventId, Entry> entries_;  // live events; a queued id not here was cancelled
  double now_ = 0.0;
  std::uint64_t next_order_ = 0;
  EventId next_id_ = 1;
  std::uint64_t events_run_ = 0;
  Pacing pacing_;
  bool pace_started_ = false;
  double pace_t0_ = 0.0;
  std::chrono::steady_clock::time_point pace_wall0_;
  bool stop_ = false;
  EventId running_ = 0;         // the event whose action is executing
  bool cancel_running_ = false;  // erase it when the action returns
};

}  // namespace viewline::runtime
