#include "viewline/runtime/live.h"

#include <time.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <thread>
#include <utility>

#include "viewline/core/error.h"
#include "viewline/core/statistics.h"

namespace viewline::runtime {

namespace {

class SteadyWallClock : public WallClock {
public:
  double now() const override {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
  }
  void sleepUntil(double t) override {
    const auto until = std::chrono::steady_clock::time_point(
        std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(t)));
    std::this_thread::sleep_until(until);
  }
};

TimeStats statsOf(const std::vector<double>& seconds) {
  TimeStats s;
  if (seconds.empty()) return s;
  s.median_ms = 1e3 * core::percentile(seconds, 0.5);
  s.p99_ms = 1e3 * core::percentile(seconds, 0.99);
  s.max_ms = 1e3 * *std::max_element(seconds.begin(), seconds.end());
  return s;
}

/// A duration in ms as the reports print it: one decimal from 1 ms up (33.3), three significant
/// digits below (0.02), so that a sub-millisecond deadline does not print as 0.0.
std::string msText(double seconds) {
  char text[32];
  const double ms = 1e3 * seconds;
  std::snprintf(text, sizeof text, ms >= 1.0 ? "%.1f" : "%.3g", ms);
  return text;
}

}  // namespace

WallClock& steadyWallClock() {
  static SteadyWallClock clock;
  return clock;
}

double threadCpuSeconds() {
  timespec ts{};
  ::clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// ---------------------------------------------------------------------------- PacedSource

PacedSource::PacedSource(std::unique_ptr<FrameSource> footage, double factor, std::string what, WallClock* clock)
    : footage_(std::move(footage)), factor_(factor), what_(std::move(what)),
      clock_(clock != nullptr ? clock : &steadyWallClock()) {
  if (!footage_) throw core::InvalidInput("PacedSource: no footage");
  if (!(factor_ > 0.0) || !std::isfinite(factor_))
    throw core::InvalidInput("PacedSource: the pace factor must be > 0 (got " + std::to_string(factor_) + ")");
}

std::optional<Frame> PacedSource::grab() {
  const std::optional<core::Timestamp> next = footage_->nextReadyTime();
  if (!next) return std::nullopt;
  if (!started_) {  // the first frame arrives now: the footage's clock starts with the loop
    started_ = true;
    wall0_ = clock_->now();
    stamp0_ = *next;
  }
  if (clock_->now() < arrival(*next)) clock_->sleepUntil(arrival(*next));
  std::optional<Frame> frame = footage_->grab();
  // Newer frames that arrived while the loop was busy: the camera would have overwritten this one.
  // (The footage is read to learn the next stamp, so a frame passed over is still decoded; the
  // time it takes is spent in grab(), never counted as processing.)
  while (true) {
    const std::optional<core::Timestamp> after = footage_->nextReadyTime();
    if (!after || arrival(*after) > clock_->now()) break;
    ++dropped_;
    frame = footage_->grab();
  }
  ++handed_out_;  // a frame the footage lost (nullopt) is handed out as lost, as a camera's would be
  return frame;
}

std::string PacedSource::describe() const {
  char text[64];
  std::snprintf(text, sizeof text, " played as a live camera at %gx its stamps' rate", factor_);
  return what_ + text;
}

// ---------------------------------------------------------------------------- ProcessingTimer

ProcessingTimer::ProcessingTimer(double deadline_s, WallClock* clock)
    : deadline_s_(deadline_s), clock_(clock != nullptr ? clock : &steadyWallClock()) {
  if (!(deadline_s_ > 0.0) || !std::isfinite(deadline_s_))
    throw core::InvalidInput("frame deadline must be > 0 s (got " + std::to_string(deadline_s_) + ")");
}

void ProcessingTimer::resume(std::uint64_t id) {
  Running& r = in_flight_[id];
  if (r.running) return;
  r.running = true;
  r.wall_at = clock_->now();
  r.cpu_at = threadCpuSeconds();
}

void ProcessingTimer::pause(std::uint64_t id) {
  const auto it = in_flight_.find(id);
  if (it == in_flight_.end() || !it->second.running) return;
  Running& r = it->second;
  r.wall += clock_->now() - r.wall_at;
  r.cpu += threadCpuSeconds() - r.cpu_at;
  r.running = false;
}

void ProcessingTimer::finish(std::uint64_t id) {
  pause(id);
  const auto it = in_flight_.find(id);
  if (it == in_flight_.end()) return;
  wall_s_.push_back(it->second.wall);
  cpu_s_.push_back(it->second.cpu);
  if (it->second.wall > deadline_s_) ++late_;
  in_flight_.erase(it);
}

TimeStats ProcessingTimer::wall() const { return statsOf(wall_s_); }
TimeStats ProcessingTimer::cpu() const { return statsOf(cpu_s_); }

// ---------------------------------------------------------------------------- LiveReport

std::string liveStatus(const LiveFrameSource& source, const ProcessingTimer& timer) {
  char text[160];
  std::snprintf(text, sizeof text, "missed %llu of %llu frames (deadline %s ms), last %.1f ms",
                static_cast<unsigned long long>(source.dropped() + timer.late()),
                static_cast<unsigned long long>(source.delivered()), msText(timer.deadline()).c_str(), timer.lastWallMs());
  return text;
}

LiveReport liveReport(const LiveFrameSource& source, const ProcessingTimer& timer, const std::string& deadline_origin) {
  LiveReport r;
  r.source = source.describe();
  r.deadline_s = timer.deadline();
  r.deadline_origin = deadline_origin;
  r.delivered = source.delivered();
  r.processed = timer.frames();
  r.dropped = source.dropped();
  r.late = timer.late();
  r.queued_late = source.queuedLate();
  r.wall = timer.wall();
  r.cpu = timer.cpu();
  return r;
}

nlohmann::json toJson(const LiveReport& r) {
  const auto stats = [](const TimeStats& s) {
    return nlohmann::json{{"median", s.median_ms}, {"p99", s.p99_ms}, {"max", s.max_ms}};
  };
  return {{"source", r.source},
          {"deadline_s", r.deadline_s},
          {"deadline", r.deadline_origin},
          {"frames_delivered", r.delivered},
          {"frames_processed", r.processed},
          {"frames_dropped", r.dropped},
          {"frames_late", r.late},
          {"frames_missed", r.missed()},
          {"frames_queued_late", r.queued_late},
          {"processing_wall_ms", stats(r.wall)},
          {"processing_cpu_ms", stats(r.cpu)}};
}

std::string summaryLine(const LiveReport& r) {
  char text[400];
  std::snprintf(text, sizeof text,
                "live: %llu of %llu frames missed their %s ms deadline (%s): %llu dropped while busy, %llu processed late",
                static_cast<unsigned long long>(r.missed()), static_cast<unsigned long long>(r.delivered),
                msText(r.deadline_s).c_str(), r.deadline_origin.c_str(), static_cast<unsigned long long>(r.dropped),
                static_cast<unsigned long long>(r.late));
  std::string line = text;
  if (r.queued_late > 0) line += "; " + std::to_string(r.queued_late) + " handed out over a period after capture";
  return line;
}

std::string processingLine(const LiveReport& r) {
  char text[300];
  std::snprintf(text, sizeof text,
                "processing per frame (ms, %llu frames): wall median %.2f p99 %.2f max %.2f; CPU median %.2f p99 %.2f max %.2f",
                static_cast<unsigned long long>(r.processed), r.wall.median_ms, r.wall.p99_ms, r.wall.max_ms,
                r.cpu.median_ms, r.cpu.p99_ms, r.cpu.max_ms);
  return text;
}

}  // namespace viewline::runtime
