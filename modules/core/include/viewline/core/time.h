#pragma once
// Time stamps. Every measurement carries the capture time of its image in
// seconds on a monotonic clock; there is no global clock: simulation time is
// passed in by whoever owns the loop.

namespace viewline::core {

/// Seconds on a monotonic clock (simulation time in the simulated worlds).
using Timestamp = double;

}  // namespace viewline::core
