#pragma once
// Progress of a long run, readable on a terminal and in a log file alike.
//
// On a terminal the line redraws in place ("\r  throws 37 / 100"); when the stream is a file or a
// pipe, "\r" would turn into one garbled line, so plain lines are printed instead, no more often
// than every `min_interval_s` of wall time or every 10 % of the work, and always the last one.
//
//   runtime::Progress progress("throws", total);   // stderr; silent with Progress::quiet()
//   for (...) progress.update(done);
//   progress.finish();

#include <chrono>
#include <cstdio>
#include <string>

namespace viewline::runtime {

/// Progress line of a long run ("throws 37 / 100"): redrawn in place on a terminal, plain rate-limited lines in a log.
class Progress {
public:
  /// Reports "<what> <done> / <total>" on `out` (stderr by default). `interactive`: -1 asks
  /// isatty() on the stream, 0 forces plain lines, 1 forces in-place redraws.
  Progress(std::string what, long total, std::FILE* out = stderr, int interactive = -1,
           double min_interval_s = 10.0);
  /// A Progress that prints nothing.
  static Progress quiet();
  ~Progress();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;
  /// Takes over another progress line (the moved-from one prints nothing more).
  Progress(Progress&&) noexcept;
  Progress& operator=(Progress&&) = delete;

  /// Thread-safe only when called from one thread at a time (callers serialise).
  void update(long done);
  /// Ends the line (the last count is printed if it was not). Idempotent.
  void finish();
  /// True when the line redraws in place (a terminal).
  bool interactive() const { return interactive_; }

private:
  Progress() = default;
  void print(long done);
  std::string what_;
  long total_ = 0;
  std::FILE* out_ = nullptr;
  bool interactive_ = false;
  double min_interval_s_ = 10.0;
  long last_printed_ = 0;
  bool printed_any_ = false;
  long last_done_ = -1;
  std::chrono::steady_clock::time_point last_wall_;
  bool finished_ = false;
};

}  // namespace viewline::runtime
