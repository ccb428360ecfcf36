#pragma once
// A process-wide "stop now" request, set by a signal handler (SIGINT from Ctrl-C, SIGTERM from a
// job manager) and polled by whatever runs long: the runtime's Scheduler returns before its next
// event, the scenario loops end after their current run, and the summary written afterwards says
// `"interrupted": true`. The flag lives in the ground layer because every layer polls it (io marks
// the summary, runtime stops the clock, the apps install the handler and choose the exit status).
//
// Async-signal-safety: a handler may only touch lock-free atomics (or volatile sig_atomic_t);
// std::atomic<int> is lock-free on every platform we build for, checked below.

#include <atomic>

namespace viewline::core {

namespace detail {
/// The signal number that asked for the stop; 0 when none did.
inline std::atomic<int> interrupt_signal{0};
static_assert(std::atomic<int>::is_always_lock_free, "the interrupt flag must be usable from a signal handler");
}  // namespace detail

/// Records that signal `sig` (> 0) asked the process to stop. Async-signal-safe.
inline void noteInterrupt(int sig) noexcept { detail::interrupt_signal.store(sig, std::memory_order_relaxed); }

/// The signal that asked the process to stop (e.g. SIGINT = 2, SIGTERM = 15); 0 when none did.
inline int interruptSignal() noexcept { return detail::interrupt_signal.load(std::memory_order_relaxed); }

/// Whether a signal asked the process to stop.
inline bool interruptRequested() noexcept { return interruptSignal() != 0; }

/// Forgets a recorded stop request (tests, or a tool that handled it and goes on).
inline void clearInterrupt() noexcept { detail::interrupt_signal.store(0, std::memory_order_relaxed); }

}  // namespace viewline::core
