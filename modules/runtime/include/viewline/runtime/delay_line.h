#pragma once
// A latency: values that become available at a later time, handed over in the order they
// were sent. Models a processing or transport delay between a producer (the tracker after a
// frame) and a consumer that polls at its own rate (a controller at its period), the way a
// real controller reads the newest message at each cycle.
//
//   runtime::DelayLine<Estimate> to_planner;
//   to_planner.send(frame.stamp + processing_latency, tracker.state());   // producer
//   to_planner.receive(t_tick, [&](double t_avail, const Estimate& e) { planner.update(t_avail, e); });

#include <deque>
#include <utility>

#include "viewline/core/error.h"

namespace viewline::runtime {

template <typename T>
/// A FIFO latency: values of type T sent with an availability time (s) and received once the consumer's time
/// reaches it.
class DelayLine {
public:
  /// Queues `value`, available from `t_available` on. Deliveries keep the order of sending, so
  /// a value sent later never overtakes an earlier one (FIFO, as a single link). Throws for a
  /// NaN time.
  void send(double t_available, T value) {
    if (t_available != t_available) throw core::InvalidInput("DelayLine::send: NaN availability time");
    queue_.emplace_back(t_available, std::move(value));
  }

  /// Hands every value available at time t (t_available <= t), oldest first, to
  /// f(t_available, value), and forgets it. Stops at the first value not yet available (FIFO).
  /// Returns the number delivered.
  template <typename F>
  std::size_t receive(double t, F&& f) {
    std::size_t n = 0;
    while (!queue_.empty() && queue_.front().first <= t) {
      // Moved out before the call: the consumer may send again on the same line.
      std::pair<double, T> item = std::move(queue_.front());
      queue_.pop_front();
      f(item.first, item.second);
      ++n;
    }
    return n;
  }

  /// True when no value is in flight.
  bool empty() const { return queue_.empty(); }
  /// Number of values in flight.
  std::size_t size() const { return queue_.size(); }
  /// Availability time of the oldest value in flight (undefined when empty()).
  double nextAvailable() const { return queue_.front().first; }
  /// Drops every value in flight.
  void clear() { queue_.clear(); }

private:
  std::deque<std::pair<double, T>> queue_;
};

}  // namespace viewline::runtime
