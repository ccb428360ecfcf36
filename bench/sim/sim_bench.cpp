// Rendering speed of the simulated worlds.
//
// Requirement: a 10 s, 2-camera, 50 Hz ball scenario at 656x480 renders at least 10x
// faster than real time, i.e. the 1000 frames in < 1 s. BM_BallScenario runs exactly that, with a
// fresh rig each iteration (so the static-layer render of both cameras is included), and reports
// the real-time factor (from the benchmark thread's CPU time; the static layers are rendered in
// parallel bands on OpenCV's thread pool, so process_cpu_ms gives the total CPU of all threads
// and Time the wall clock). Variants add the imaging effects; the per-frame benchmarks isolate
// the costs.
//
//   cmake --build build-sim -j2 --target sim_bench && build-sim/bench/sim_bench

#include <benchmark/benchmark.h>

#include <ctime>

#include "viewline/core/frames.h"
#include "viewline/sim/rig.h"
#include "viewline/sim/worlds.h"

using namespace viewline;
using namespace viewline::sim;

namespace {

constexpr double kDuration = 10.0;

// Eight throws of the 5 cm ball across the room, one every 1.25 s, each 1.2 s long.
BallFlightWorld ballWorld() {
  core::Rng rng = core::makeRng(2024);
  std::vector<DragFlight> flights;
  for (int i = 0; i < 8; ++i) {
    const double dir = (i % 2 == 0) ? 1.0 : -1.0;
    const FlightState s0{{-1.8 * dir, 0.3 * (i % 3), 1.0}, {3.0 * dir, 0.4, 5.0}};
    flights.emplace_back(s0, 1.25 * i, 1.2, DragBody::ball5cm());
  }
  return BallFlightWorld(std::move(flights), makeRoom(RoomParams{}, rng));
}

SimCamera camera656(const std::string& name, const Eigen::Vector3d& eye, double phase) {
  SimCamera c;
  c.camera.name = name;
  c.camera.width = 656;
  c.camera.height = 480;
  c.camera.intrinsics = vpCameraParameters(600.0, 600.0, 328.0, 240.0, -0.05, 0.05);
  c.camera.c_M_w = core::lookAt(eye, {0.0, 0.0, 1.5}, Eigen::Vector3d::UnitZ());
  c.clock.rate = 50.0;
  c.clock.phase = phase;
  return c;
}

std::vector<SimCamera> twoCameras(bool effects) {
  std::vector<SimCamera> cams{camera656("cam1", {-2.5, -4.0, 1.5}, 0.0), camera656("cam2", {2.5, -4.0, 1.5}, 0.01)};
  if (effects) {
    for (auto& c : cams) {
      c.effects.noise.sigma = 3.0;
      c.effects.blur.exposure = 0.005;
      c.effects.blur.samples = 5;
      c.effects.illumination.gain = 0.9;
      c.effects.illumination.white_balance_bgr = Eigen::Vector3d(1.05, 1.0, 0.95);
      c.effects.faults.stamp_jitter = 2e-4;
    }
  }
  return cams;
}

void runScenario(benchmark::State& state, bool effects) {
  const BallFlightWorld world = ballWorld();
  std::size_t frames = 0;
  std::size_t ball_visible = 0;
  const std::clock_t c0 = std::clock();  // process CPU time, all threads (OpenCV pool included)
  for (auto _ : state) {
    core::Rng rng = core::makeRng(7);
    CameraRig rig(twoCameras(effects), rng);  // cold caches: static layers rendered in the loop
    frames = rig.run(world, 0.0, kDuration, [&](Frame&& f) {
      const ObjectTruth* b = f.find("ball");
      if (b != nullptr && b->in_image) ++ball_visible;
      benchmark::DoNotOptimize(f.image.data);
    });
  }
  const double per_iter = static_cast<double>(state.iterations());
  state.counters["process_cpu_ms"] = 1e3 * static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC / per_iter;
  state.counters["frames"] = static_cast<double>(frames);
  state.counters["ball_in_image_pct"] = 100.0 * static_cast<double>(ball_visible) / (per_iter * static_cast<double>(frames));
  state.counters["frames_per_s"] = benchmark::Counter(static_cast<double>(frames), benchmark::Counter::kIsIterationInvariantRate);
  state.counters["realtime_factor"] =
      benchmark::Counter(kDuration, benchmark::Counter::kIsIterationInvariantRate);
}

void BM_BallScenario_10s_2cams_50Hz_656x480(benchmark::State& state) { runScenario(state, false); }
void BM_BallScenario_10s_2cams_50Hz_656x480_Effects(benchmark::State& state) { runScenario(state, true); }

// One warm frame (static layer cached) of the ball scenario.
void BM_BallFrameWarm_656x480(benchmark::State& state) {
  const BallFlightWorld world = ballWorld();
  Renderer renderer;
  const core::Camera cam = camera656("cam1", {-2.5, -4.0, 1.5}, 0.0).camera;
  renderer.render(world, cam, {0.6, 0.0, 1});
  double t = 0.0;
  for (auto _ : state) {
    t = t > 9.9 ? 0.0 : t + 0.02;
    cv::Mat img = renderer.render(world, cam, {t, 0.0, 1});
    benchmark::DoNotOptimize(img.data);
  }
}

// The static layer (textured floor and wall) of one 656x480 camera, rendered from scratch.
void BM_StaticLayerCold_656x480(benchmark::State& state) {
  const BallFlightWorld world = ballWorld();
  const core::Camera cam = camera656("cam1", {-2.5, -4.0, 1.5}, 0.0).camera;
  for (auto _ : state) {
    Renderer renderer;
    cv::Mat img = renderer.render(world, cam, {20.0, 0.0, 1});
    benchmark::DoNotOptimize(img.data);
  }
}

// [M]'s table scene, 320x240: the table moves, so every frame ray-casts the table and the ball.
void BM_TableFrame_320x240(benchmark::State& state) {
  core::Rng rng = core::makeRng(3);
  TiltTableParams tp;
  tp.w_M_base.translation() = Eigen::Vector3d(0.0, 0.0, 0.8);
  TiltTable table(tp);
  const TableWorld world(table, makeRoom(RoomParams{}, rng));
  core::Camera cam;
  cam.width = 320;
  cam.height = 240;
  cam.intrinsics = core::intrinsicsFromFov(core::deg2rad(90.0), 320, 240);
  cam.c_M_w = core::lookAt({0.05, -0.35, 1.3}, {0.0, 0.0, 0.8}, Eigen::Vector3d::UnitZ());
  Renderer renderer;
  double t = 0.0;
  for (auto _ : state) {
    t += 0.02;
    table.command(t, Eigen::Vector2d(0.1 * std::sin(t), 0.1 * std::cos(t)));
    table.advanceTo(t);
    cv::Mat img = renderer.render(world, cam, {t, 0.0, 1});
    benchmark::DoNotOptimize(img.data);
  }
}

}  // namespace

BENCHMARK(BM_BallScenario_10s_2cams_50Hz_656x480)->Unit(benchmark::kMillisecond)->MinTime(3.0);
BENCHMARK(BM_BallScenario_10s_2cams_50Hz_656x480_Effects)->Unit(benchmark::kMillisecond)->MinTime(3.0);
BENCHMARK(BM_BallFrameWarm_656x480)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_StaticLayerCold_656x480)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_TableFrame_320x240)->Unit(benchmark::kMicrosecond);

BENCHMARK_MAIN();
