// No allocation in the steady-state hot path: a replaceable global operator new counts heap
// allocations of this thread while detect + track + plan (catch_pipeline.h) processes tracked
// frames of recorded ball-catching throws, after a warm-up pass. Tracked frame: the tracker holds
// a track and the detector found the ball in the window around its prediction. The count per
// stage is printed, and the test fails when a stage allocates more per tracked frame than its
// limit: by default what the stages reach (tracker and planner none; the detection's are
// OpenCV's findContours storage and inRange's buffer, docs/results.md, Latency), so that a change
// which allocates more fails. Eigen's dynamic matrices take their storage from malloc, not
// operator new, and are not counted here.
//
//   build/bench/latency_alloc_test [--frames 1000] [--config FILE] [--trace N]
//       [--max-detection A] [--max-tracker A] [--max-planner A]
//
// --trace N prints the call stack (glibc backtrace, to stderr) of the first N counted
// allocations: where the hot path still allocates. --max-* set the limits (allocations per
// tracked frame, mean over the frames).

#include <opencv2/core/utility.hpp>

#include <execinfo.h>

#include <cstdio>
#include <cstdlib>
#include <new>
#include <string>

#include "catch_pipeline.h"

#ifndef VIEWLINE_SOURCE_DIR
#error "VIEWLINE_SOURCE_DIR must name the source tree (for the default config)"
#endif

namespace {

// Allocations per tracked frame the detection reaches (OpenCV's findContours, its border copy,
// and inRange's scratch buffer; a cv::Mat resized where the window is clipped at the image edge).
constexpr double kDetectionLimit = 3.198;

// Counting is per thread and only while armed (OpenCV's and the renderer's worker threads, and
// everything outside the measured frames, are not counted).
thread_local bool g_armed = false;
thread_local std::size_t g_count = 0;
std::size_t g_trace = 0;  // call stacks still to print (--trace)

void traceAllocation(std::size_t n) {
  if (g_trace == 0) return;
  --g_trace;
  g_armed = false;  // backtrace() may allocate on its first call
  void* frames[24];
  const int depth = backtrace(frames, 24);
  std::fprintf(stderr, "allocation of %zu bytes:\n", n);
  backtrace_symbols_fd(frames, depth, 2);
  g_armed = true;
}

// process() takes a clock: this one returns the allocation count (as a "time"), so the stage
// split of the count comes for free.
double allocationClock() { return static_cast<double>(g_count); }

void* allocate(std::size_t n) {
  if (g_armed) {
    ++g_count;
    traceAllocation(n);
  }
  if (void* p = std::malloc(n == 0 ? 1 : n)) return p;
  throw std::bad_alloc();
}

void* allocateAligned(std::size_t n, std::align_val_t al) {
  if (g_armed) {
    ++g_count;
    traceAllocation(n);
  }
  const auto a = static_cast<std::size_t>(al);
  if (void* p = std::aligned_alloc(a, (n + a - 1) / a * a)) return p;
  throw std::bad_alloc();
}

}  // namespace

void* operator new(std::size_t n) { return allocate(n); }
void* operator new[](std::size_t n) { return allocate(n); }
void* operator new(std::size_t n, const std::nothrow_t&) noexcept {
  try {
    return allocate(n);
  } catch (...) {
    return nullptr;
  }
}
void* operator new[](std::size_t n, const std::nothrow_t&) noexcept {
  try {
    return allocate(n);
  } catch (...) {
    return nullptr;
  }
}
void* operator new(std::size_t n, std::align_val_t al) { return allocateAligned(n, al); }
void* operator new[](std::size_t n, std::align_val_t al) { return allocateAligned(n, al); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }

int main(int argc, char** argv) {
  using namespace viewline;
  cv::setNumThreads(1);
  std::size_t wanted = 1000;
  // The per-frame limits: what the stages reach (see the file comment).
  double max_detection = kDetectionLimit, max_tracker = 0.0, max_planner = 0.0;
  std::string config = std::string(VIEWLINE_SOURCE_DIR) + "/config/ball_catching.yaml";
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (i + 1 < argc && a == "--frames") wanted = static_cast<std::size_t>(std::atol(argv[++i]));
    else if (i + 1 < argc && a == "--config") config = argv[++i];
    else if (i + 1 < argc && a == "--trace") g_trace = static_cast<std::size_t>(std::atol(argv[++i]));
    else if (i + 1 < argc && a == "--max-detection") max_detection = std::atof(argv[++i]);
    else if (i + 1 < argc && a == "--max-tracker") max_tracker = std::atof(argv[++i]);
    else if (i + 1 < argc && a == "--max-planner") max_planner = std::atof(argv[++i]);
    else {
      std::fprintf(stderr,
                   "usage: %s [--frames N>=1] [--config FILE] [--trace N] [--max-detection A] [--max-tracker A] "
                   "[--max-planner A]\n",
                   argv[0]);
      return 2;
    }
  }
  try {
    const scenarios::BallCatchingConfig cfg = latency::catchConfig(config);
    const auto frames = latency::recordCatchFrames(cfg, 2, 1, 400);
    latency::CatchPipeline pipe(cfg);
    for (const auto& f : frames) pipe.process(f, false);  // warm-up: buffers reach their sizes
    std::size_t tracked = 0, allocating = 0, total = 0, in_detect = 0, in_track = 0, in_plan = 0, passes = 0;
    while (tracked < wanted) {
      if (++passes > 1000) throw core::Error("too few tracked frames in the recorded throws");
      pipe.reset();
      for (const auto& f : frames) {
        if (tracked >= wanted) break;
        const bool was_tracking = pipe.tracker().initialised();
        latency::CatchPipeline::StageTimes st;
        g_count = 0;
        g_armed = true;
        const bool in_window = pipe.process(f, false, &allocationClock, &st);
        g_armed = false;
        if (!was_tracking || !in_window) continue;
        ++tracked;
        total += g_count;
        allocating += g_count > 0;
        in_detect += static_cast<std::size_t>(st.detect);
        in_track += static_cast<std::size_t>(st.track);
        in_plan += static_cast<std::size_t>(st.plan);
      }
    }
    std::printf("tracked frames %zu (%zu recorded frames, %zu passes): %zu allocations, %.3f per frame, %zu frames "
                "allocating; by stage: detection %zu, tracker %zu, planner %zu\n",
                tracked, frames.size(), passes, total, static_cast<double>(total) / static_cast<double>(tracked),
                allocating, in_detect, in_track, in_plan);
    const double n = static_cast<double>(tracked);
    const double per_detection = static_cast<double>(in_detect) / n, per_tracker = static_cast<double>(in_track) / n,
                 per_planner = static_cast<double>(in_plan) / n;
    std::printf("per tracked frame: detection %.3f (limit %.3f), tracker %.3f (limit %.3f), planner %.3f (limit %.3f)\n",
                per_detection, max_detection, per_tracker, max_tracker, per_planner, max_planner);
    bool ok = true;
    const auto check = [&](const char* stage, double value, double limit) {
      if (value <= limit) return;
      std::printf("FAIL: the %s allocates %.3f per tracked frame, more than its limit %.3f\n", stage, value, limit);
      ok = false;
    };
    check("detection", per_detection, max_detection);
    check("tracker", per_tracker, max_tracker);
    check("planner", per_planner, max_planner);
    if (!ok) return 1;
    if (total == 0) std::printf("OK: no allocation in %zu tracked frames\n", tracked);
    else std::printf("OK: every stage within its limit (%zu tracked frames)\n", tracked);
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: %s\n", argv[0], e.what());
    return 1;
  }
}
