// Cost of the viewline update: one image (2 rows), 8 cameras, and 1..64 cameras
// (image-by-image: linear in the number of cameras; the stacked single update for comparison).
#include <benchmark/benchmark.h>

#include <cmath>

#include "viewline/core/frames.h"
#include "viewline/estimation/kalman_filter.h"
#include "viewline/scenarios/dart/world.h"
#include "viewline/tracking/tracker.h"

using namespace viewline;
using namespace viewline::tracking;

namespace {

std::vector<core::Camera> ring(int n) {
  std::vector<core::Camera> cams;
  for (int i = 0; i < n; ++i) {
    const double a = 2.0 * core::kPi * i / n;
    core::Camera c;
    c.width = 656;
    c.height = 480;
    const vpCameraParameters pin = core::intrinsicsFromFov(core::deg2rad(62.0), 656, 480);
    c.intrinsics = vpCameraParameters(pin.get_px(), pin.get_py(), pin.get_u0(), pin.get_v0(), 0.02, -0.02);
    c.c_M_w = core::lookAt({1.2 + 2.7 * std::cos(a), 2.7 * std::sin(a), 1.6 + 0.3 * std::sin(3 * a)},
                           {1.2, 0.0, 1.75}, Eigen::Vector3d::UnitZ());
    cams.push_back(c);
  }
  return cams;
}

struct Setup {
  std::vector<core::Camera> cams;
  std::vector<ImageMeasurement> meas;
  Vector6 x;
  Matrix6 P;
  explicit Setup(int n) : cams(ring(n)) {
    const Eigen::Vector3d p(1.25, 0.05, 1.78);
    for (int i = 0; i < n; ++i) {
      const Eigen::Vector3d pc = cams[static_cast<std::size_t>(i)].c_M_w * p;
      meas.push_back({static_cast<std::uint64_t>(i), static_cast<std::size_t>(i), 0.0,
                      exactPixelOf(cams[static_cast<std::size_t>(i)], {pc.x() / pc.z(), pc.y() / pc.z()}), 0.5});
    }
    x << 1.2, 0.0, 1.75, 12.0, 0.0, 0.0;
    P = 0.01 * Matrix6::Identity();
  }
};

// One image: rows, gates, square-root update (what ViewlineTracker does per image).
void BM_UpdateOneImage(benchmark::State& st) {
  Setup s(1);
  const BallisticModel model;
  GateConfig gate;
  for (auto _ : st) {
    estimation::StateEstimate e(s.x, s.P);
    benchmark::DoNotOptimize(fuseImage(e, s.cams[0], s.meas[0], model, gate, 0.0, 0.05, false));
  }
}
BENCHMARK(BM_UpdateOneImage);

// n cameras at one instant, image by image (each gated on its own).
void BM_UpdateCameras(benchmark::State& st) {
  const int n = static_cast<int>(st.range(0));
  Setup s(n);
  const BallisticModel model;
  GateConfig gate;
  for (auto _ : st) {
    estimation::StateEstimate e(s.x, s.P);
    for (int i = 0; i < n; ++i)
      benchmark::DoNotOptimize(fuseImage(e, s.cams[static_cast<std::size_t>(i)], s.meas[static_cast<std::size_t>(i)],
                                         model, gate, 0.0, 0.05, false));
  }
  st.SetComplexityN(n);
}
BENCHMARK(BM_UpdateCameras)->Arg(8)->RangeMultiplier(2)->Range(1, 64)->Complexity(benchmark::oN);

// The same as one stacked update (2n rows, block-diagonal R, no gating): superlinear.
void BM_UpdateCamerasStacked(benchmark::State& st) {
  const int n = static_cast<int>(st.range(0));
  Setup s(n);
  const BallisticModel model;
  for (auto _ : st) {
    estimation::StateEstimate e(s.x, s.P);
    std::vector<ViewlineRows> rows;
    for (int i = 0; i < n; ++i)
      rows.push_back(viewlineRows(s.cams[static_cast<std::size_t>(i)], s.meas[static_cast<std::size_t>(i)].uv, 0.5,
                                  s.x, s.P, 0.0, model));
    benchmark::DoNotOptimize(estimation::update(e, stackRows(rows)));
  }
  st.SetComplexityN(n);
}
BENCHMARK(BM_UpdateCamerasStacked)->RangeMultiplier(2)->Range(1, 64)->Complexity();

// The whole tracker path (validation, buffer, snapshot, propagation, gate, update) per image, on
// dart flights of the shipped scenario (alternating cameras); a new tracker per flight (untimed).
void BM_TrackerSubmitDartFlight(benchmark::State& st) {
  const scenarios::DartScenarioConfig cfg = scenarios::defaultDartScenario();
  const std::vector<core::Camera> cams = scenarios::makeDartCameras(cfg);
  core::Rng rng = core::makeRng(1);
  const scenarios::DartFlight flight =
      scenarios::simulateDartFlight(cfg, cams, scenarios::DartClockMode::Alternating, 0.0, rng);
  std::size_t i = 0;
  ViewlineTracker tr(cams, cfg.trackerConfig());
  for (auto _ : st) {
    if (i == flight.detections.size()) {
      st.PauseTiming();
      tr.reset();
      i = 0;
      st.ResumeTiming();
    }
    benchmark::DoNotOptimize(tr.submit(flight.detections[i++].m));
  }
}
BENCHMARK(BM_TrackerSubmitDartFlight);

}  // namespace

BENCHMARK_MAIN();
