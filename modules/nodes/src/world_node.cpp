#include <thread>

#include "node_common.h"
#include "viewline/core/error.h"
#include "viewline/nodes/simulation.h"

namespace viewline::nodes {

using detail::NodeContext;

nlohmann::json runWorldNode(const scenarios::BallCatchingConfig& cfg, const NodeOptions& opt) {
  if (!(opt.tick_s > 0.0) || !(opt.duration_s > 0.0) || !(opt.realtime > 0.0))
    throw core::InvalidInput("world: --tick, --duration and --realtime must be > 0");
  NodeContext ctx(opt, "world", "world", rigHash(cfg));
  // Keep-last 4 (clock) and 64 (truth, 0.13 s at the default tick): a camera must see every tick.
  dds::Writer<ClockMsg> clock_w(ctx.participant, ctx.clock_topic, dds::Qos::state(4));
  dds::Writer<ObjectTruthMsg> truth_w(ctx.participant, ctx.truth_topic, dds::Qos::state(64));
  const WorldTruth truth(cfg, opt.seed, opt.release_s);
  ctx.publishHealth(HealthStatus::Starting, "waiting for " + std::to_string(opt.expect) + " nodes", 0.0);

  // Discovery: start once `expect` nodes follow the clock, then leave the others (cameras and the
  // tracker find each other at the same time) a moment to match.
  while (clock_w.matched().current < opt.expect) {
    if (ctx.shouldStop())
      throw core::Error("world: only " + std::to_string(clock_w.matched().current) + " of " +
                        std::to_string(opt.expect) + " nodes followed rt/clock before the end (check CYCLONEDDS_URI)");
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  ctx.takeHealth();
  ctx.log("%d nodes follow the clock; running %.2f s of simulated time at %.2fx real time", clock_w.matched().current,
          opt.duration_s, opt.realtime);
  ctx.publishHealth(HealthStatus::Running, "running", 0.0);

  const auto wall0 = std::chrono::steady_clock::now();
  std::uint64_t ticks = 0, truth_samples = 0;
  const std::string ball = cfg.object;
  bool interrupted = false;
  for (std::uint64_t j = 0;; ++j) {
    const double t = static_cast<double>(j) * opt.tick_s;  // not accumulated: camera nodes see the same grid
    if (t > opt.duration_s) break;
    if (ctx.shouldStop()) {
      interrupted = true;
      break;
    }
    std::this_thread::sleep_until(wall0 + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                              std::chrono::duration<double>(t / opt.realtime)));
    ClockMsg c{};
    c.clock = toTimeMsg(t);
    clock_w.write(c);
    ObjectTruthMsg m{};
    m.header.stamp = c.clock;
    m.header.frame_id = messageString(ball);
    m.in_flight = truth.inFlight(t);
    if (m.in_flight) {
      const sim::FlightState s = truth.state(t);
      for (int k = 0; k < 3; ++k) {
        m.position[k] = s.p(k);
        m.velocity[k] = s.v(k);
      }
    }
    truth_w.write(m);
    ++ticks;
    truth_samples += m.in_flight ? 1 : 0;
  }
  ctx.publishHealth(HealthStatus::Finished, interrupted ? "interrupted" : "done", opt.duration_s);
  ctx.log("finished after %llu ticks", static_cast<unsigned long long>(ticks));
  // Reliable and transient-local: give the Finished a moment to reach every reader before leaving.
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  const sim::FlightState cross = truth.state(truth.crossingTime());
  nlohmann::json j;
  j["role"] = "world";
  j["rig_hash"] = detail::hex(ctx.rig_hash);
  j["ticks"] = ticks;
  j["ticks_in_flight"] = truth_samples;
  j["tick_s"] = opt.tick_s;
  j["release_s"] = opt.release_s;
  j["crossing_time_s"] = truth.crossingTime();
  j["crossing_point_m"] = {cross.p.x(), cross.p.y(), cross.p.z()};
  j["interrupted"] = interrupted;
  j["wall_s"] = ctx.wallSeconds();
  return detail::finish(opt, j);
}

}  // namespace viewline::nodes
