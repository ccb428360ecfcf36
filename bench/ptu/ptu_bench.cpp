// Command throughput of robots::FlirPtu against robots::FlirPtuEmulator (in-process, on its own
// thread). Each benchmark repeats one exchange: a command line written at once, then one reply
// line per command read back (the driver drains stale bytes first, so exchanges never overlap):
//   Query   "PP"           1 command per exchange (a position query)
//   Command "PSn TSm"      2 commands (a velocity command, what the pan-tilt loop sends per frame)
//   Read    "PP TP PD TD"  4 commands (the joint state read)
// over link 0: pty without a line-rate limit, 1: pty at 115200 baud emulated, 2: pty at 9600 baud
// emulated (10 bit times per byte in and out), 3: loopback TCP. Wall-clock time (the driver waits
// on I/O): commands_per_s counts commands, not exchanges.
//
//   build/bench/ptu_bench --benchmark_min_time=1
#include <benchmark/benchmark.h>

#include <memory>
#include <string>

#include "viewline/robots/flir_ptu.h"
#include "viewline/robots/ptu_emulator.h"

using namespace viewline::robots;

namespace {

struct Rig {
  FlirPtuEmulator emu;
  std::unique_ptr<FlirPtu> ptu;
  std::string label;
  explicit Rig(int link) {
    FlirPtuConfig c;
    c.reply_timeout = 1.0;
    static const int kBaud[] = {0, 115200, 9600};
    if (link < 3) {
      c.port = emu.openPty();
      c.baud = link == 2 ? 9600 : 115200;
      emu.setBaud(kBaud[link]);
      label = link == 0 ? "pty, no line-rate limit" : "pty, " + std::to_string(kBaud[link]) + " baud emulated";
    } else {
      c.tcp = "127.0.0.1:" + std::to_string(emu.listenTcp(0));
      label = "tcp loopback";
    }
    emu.start();
    ptu = std::make_unique<FlirPtu>(c);
  }
};

void report(benchmark::State& state, const Rig& rig, int commands_per_exchange) {
  const auto commands = static_cast<double>(state.iterations()) * commands_per_exchange;
  state.counters["commands_per_s"] = benchmark::Counter(commands, benchmark::Counter::kIsRate);
  state.SetLabel(rig.label);
}

void BM_Query(benchmark::State& state) {
  Rig rig(static_cast<int>(state.range(0)));
  for (auto _ : state) benchmark::DoNotOptimize(rig.ptu->exchange({"PP"}));
  report(state, rig, 1);
}

void BM_Command(benchmark::State& state) {
  Rig rig(static_cast<int>(state.range(0)));
  double t = 0.0;
  int k = 0;
  for (auto _ : state) {
    t += 1e-3;
    rig.ptu->commandVelocity(t, Eigen::Vector2d((++k % 2) ? 0.01 : -0.01, 0.0));  // stays near home
  }
  report(state, rig, 2);
}

void BM_Read(benchmark::State& state) {
  Rig rig(static_cast<int>(state.range(0)));
  double t = 0.0;  // a new time each read: a read at the same time is answered from the last sample
  for (auto _ : state) benchmark::DoNotOptimize(rig.ptu->read(t += 1e-3));
  report(state, rig, 4);
}

}  // namespace

BENCHMARK(BM_Query)->DenseRange(0, 3)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Command)->DenseRange(0, 3)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Read)->DenseRange(0, 3)->UseRealTime()->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();
