#pragma once
// Timing helpers shared by the latency benches: per-thread CPU time (one core, what a frame
// costs the process; preemption by other processes on a loaded machine is not counted) and the
// order statistics the figures report (median, p99).

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <string>
#include <vector>

namespace viewline::latency {

/// CPU time of the calling thread, s (CLOCK_THREAD_CPUTIME_ID: about 0.1-0.3 µs per call).
inline double threadCpuNow() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

/// Order statistics of a sample of durations, s.
struct Stats {
  std::size_t n = 0;    ///< sample size
  double median = 0.0;  ///< s
  double p99 = 0.0;     ///< s, 99th percentile (nearest rank)
  double mean = 0.0;    ///< s
  double min = 0.0;     ///< s
  double max = 0.0;     ///< s
};

/// Nearest-rank quantile q in [0, 1] of a sorted sample.
inline double quantileSorted(const std::vector<double>& sorted, double q) {
  if (sorted.empty()) return std::nan("");
  const auto rank = static_cast<std::size_t>(std::ceil(q * static_cast<double>(sorted.size())));
  return sorted[std::min(sorted.size() - 1, rank == 0 ? 0 : rank - 1)];
}

/// Median, p99, mean, min and max of `samples` (s); the vector is sorted in place.
inline Stats summarise(std::vector<double>& samples) {
  Stats s;
  s.n = samples.size();
  if (samples.empty()) return s;
  std::sort(samples.begin(), samples.end());
  s.median = quantileSorted(samples, 0.5);
  s.p99 = quantileSorted(samples, 0.99);
  double sum = 0.0;
  for (double v : samples) sum += v;
  s.mean = sum / static_cast<double>(samples.size());
  s.min = samples.front();
  s.max = samples.back();
  return s;
}

/// The 1-, 5- and 15-minute load averages, as /proc/loadavg gives them ("?" when unreadable).
inline std::string loadAverage() {
  std::FILE* f = std::fopen("/proc/loadavg", "r");
  if (!f) return "?";
  char buf[128] = {0};
  const bool ok = std::fgets(buf, sizeof buf, f) != nullptr;
  std::fclose(f);
  if (!ok) return "?";
  std::string s(buf);
  // Keep the three averages only.
  std::size_t pos = 0;
  for (int k = 0; k < 3 && pos != std::string::npos; ++k) pos = s.find(' ', pos + 1);
  return s.substr(0, pos);
}

}  // namespace viewline::latency
