#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <thread>

#include "node_common.h"
#include "viewline/core/error.h"
#include "viewline/nodes/simulation.h"
#include "viewline/planning/catch_planner.h"
#include "viewline/robots/cartesian_robot.h"

namespace viewline::nodes {

using detail::NodeContext;

namespace {

// What the world hears of one episode, for its score.
struct EpisodeRecord {
  double start = 0.0, end = 0.0;
  double first_detection = -1.0;  // stamp of the first image that showed the ball, s (-1: none)
  // Robot states around the true crossing: the last one at or before it and the first after it.
  std::optional<robots::CartesianState> before, after;
};

// The hole at time t from the robot states around it: interpolated between them, or carried on
// at the nearer one's velocity when only one side arrived (robot states come every clock tick).
std::optional<Eigen::Vector3d> holeAt(const EpisodeRecord& r, double t) {
  if (r.before && r.after) {
    const double h = r.after->t - r.before->t;
    const double s = h > 1e-12 ? (t - r.before->t) / h : 0.0;
    return (1.0 - s) * r.before->p + s * r.after->p;
  }
  if (r.before && t - r.before->t < 0.01) return r.before->p + (t - r.before->t) * r.before->v;
  if (r.after && r.after->t - t < 0.01) return r.after->p - (r.after->t - t) * r.after->v;
  return std::nullopt;
}

}  // namespace

nlohmann::json runWorldNode(const scenarios::BallCatchingConfig& cfg, const NodeOptions& opt) {
  if (!(opt.tick_s > 0.0) || !(opt.duration_s > 0.0) || !(opt.realtime > 0.0))
    throw core::InvalidInput("world: --tick, --duration and --realtime must be > 0");
  if (opt.throws < 1) throw core::InvalidInput("world: --throws must be >= 1");
  NodeContext ctx(opt, "world", "world", rigHash(cfg));
  // Keep-last 4 (clock) and 64 (truth, 0.13 s at the default tick): a camera must see every tick.
  dds::Writer<ClockMsg> clock_w(ctx.participant, ctx.clock_topic, dds::Qos::state(4));
  dds::Writer<ObjectTruthMsg> truth_w(ctx.participant, ctx.truth_topic, dds::Qos::state(64));
  dds::Writer<EpisodeMsg> episode_w(ctx.participant, ctx.episode_topic, dds::Qos::health());
  // For the score: the robot's state and the cameras' detections (the first image of the ball).
  dds::Reader<RobotStateMsg> robot_r(ctx.participant, ctx.robot_topic, dds::Qos::state(256));
  dds::Reader<DetectionMsg> det_r(ctx.participant, ctx.detection_topic, dds::Qos::detections(256));

  // The session: throw i is the in-process session's throw i (same seed), released release_s
  // into episode i = [i D, (i + 1) D). Its flight and the robot's last set point must end inside.
  const double D = opt.duration_s;
  const robots::SimulatedCartesianRobot robot_model(cfg.robot);
  std::vector<WorldTruth> truths;
  std::vector<EpisodeRecord> rec(static_cast<std::size_t>(opt.throws));
  for (int i = 0; i < opt.throws; ++i) {
    const double start = i * D;
    truths.emplace_back(cfg, opt.seed, start + opt.release_s, i);
    rec[static_cast<std::size_t>(i)].start = start;
    rec[static_cast<std::size_t>(i)].end = start + D;
    if (truths.back().endTime() + robot_model.commandLatency() > start + D)
      throw core::InvalidInput("world: throw " + std::to_string(i) + " ends " +
                               std::to_string(truths.back().endTime() - start) +
                               " s into its episode, after --duration " + std::to_string(D) + " s");
  }
  const auto episodeOf = [&](double t) {
    return std::clamp(static_cast<int>(std::floor(t / D)), 0, opt.throws - 1);
  };
  // Robot states and detections that arrived: filed under their episode.
  const auto takeScoreInputs = [&] {
    robot_r.take([&](const RobotStateMsg& m, const dds_sample_info_t&) {
      const double t = fromTimeMsg(m.header.stamp);
      EpisodeRecord& r = rec[static_cast<std::size_t>(episodeOf(t))];
      const double tc = truths[static_cast<std::size_t>(episodeOf(t))].crossingTime();
      const robots::CartesianState s{t, Eigen::Vector3d(m.position[0], m.position[1], m.position[2]),
                                     Eigen::Vector3d(m.velocity[0], m.velocity[1], m.velocity[2])};
      if (t <= tc && (!r.before || t > r.before->t)) r.before = s;
      if (t > tc && (!r.after || t < r.after->t)) r.after = s;
    });
    det_r.take([&](const DetectionMsg& d, const dds_sample_info_t&) {
      if (!d.detected) return;
      const double t = fromTimeMsg(d.header.stamp);
      EpisodeRecord& r = rec[static_cast<std::size_t>(episodeOf(t))];
      if (t >= r.start && (r.first_detection < 0.0 || t < r.first_detection)) r.first_detection = t;
    });
  };
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
  if (opt.throws == 1)
    ctx.log("%d nodes follow the clock; running %.2f s of simulated time at %.2fx real time", clock_w.matched().current, D,
            opt.realtime);
  else
    ctx.log("%d nodes follow the clock; running %d throws of %.2f s of simulated time at %.2fx real time",
            clock_w.matched().current, opt.throws, D, opt.realtime);
  ctx.publishHealth(HealthStatus::Running, "running", 0.0);

  // Each episode is announced this long before it starts (simulated time), so that every node
  // has it when the episode begins; the previous throw has ended by then (checked above).
  double announce_lead = 0.1;
  for (int i = 0; i < opt.throws; ++i)
    announce_lead = std::min(announce_lead, rec[static_cast<std::size_t>(i)].end - truths[static_cast<std::size_t>(i)].endTime() -
                                                robot_model.commandLatency());
  const auto wall0 = std::chrono::steady_clock::now();
  std::uint64_t ticks = 0, truth_samples = 0;
  const std::string ball = cfg.object;
  const std::string world_frame = "world";
  bool interrupted = false;
  int announced = -1;
  const double t_total = opt.throws * D;
  for (std::uint64_t j = 0;; ++j) {
    const double t = static_cast<double>(j) * opt.tick_s;  // not accumulated: camera nodes see the same grid
    if (t > t_total) break;
    if (ctx.shouldStop()) {
      interrupted = true;
      break;
    }
    std::this_thread::sleep_until(wall0 + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                              std::chrono::duration<double>(t / opt.realtime)));
    const int next = announced + 1;
    if (next < opt.throws && t >= rec[static_cast<std::size_t>(next)].start - announce_lead) {
      EpisodeMsg e{};
      e.header.stamp = toTimeMsg(rec[static_cast<std::size_t>(next)].start);
      e.header.frame_id = messageString(world_frame);
      e.index = static_cast<std::uint32_t>(next);
      e.count = static_cast<std::uint32_t>(opt.throws);
      e.release_time = rec[static_cast<std::size_t>(next)].start + opt.release_s;
      episode_w.write(e);
      announced = next;
      if (opt.throws > 1 && next > 0 && (next % 10 == 0 || next + 1 == opt.throws))
        ctx.log("throw %d of %d", next + 1, opt.throws);
    }
    ClockMsg c{};
    c.clock = toTimeMsg(t);
    clock_w.write(c);
    const WorldTruth& truth = truths[static_cast<std::size_t>(episodeOf(t))];
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
    takeScoreInputs();
  }
  ctx.publishHealth(HealthStatus::Finished, interrupted ? "interrupted" : "done", t_total);
  ctx.log("finished after %llu ticks", static_cast<unsigned long long>(ticks));
  // Reliable and transient-local: give the Finished a moment to reach every reader before leaving.
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  takeScoreInputs();

  // The score of each throw, by scenarios::scoreThrow's rules: caught when the hole's centre is
  // within hole radius - ball radius of the true crossing in the box plane; reachable when a
  // robot knowing the true flight from the first image of the ball, starting at home, could be
  // on the crossing point in time (limits, command latency).
  const Eigen::Vector3d& n = cfg.box_normal;
  const double clearance = cfg.hole_radius - cfg.throws.body.reference_radius;
  nlohmann::json per_throw = nlohmann::json::array();
  int scored = 0, reachable = 0, caught = 0, caught_reachable = 0, unscored = 0;
  for (int i = 0; i < opt.throws; ++i) {
    const EpisodeRecord& r = rec[static_cast<std::size_t>(i)];
    const WorldTruth& truth = truths[static_cast<std::size_t>(i)];
    if (interrupted && truth.endTime() > ticks * opt.tick_s) break;  // not run to its end
    const double tc = truth.crossingTime();
    const Eigen::Vector3d cross = truth.state(tc).p;
    const std::optional<Eigen::Vector3d> hole = holeAt(r, tc);
    nlohmann::json tj{{"index", i}, {"crossing_time_s", tc - r.start}, {"first_detection_s", nullptr}};
    if (r.first_detection >= 0.0) tj["first_detection_s"] = r.first_detection - r.start;
    if (!hole) {  // no robot node (or its states were lost): the throw cannot be scored
      ++unscored;
      tj["scored"] = false;
      per_throw.push_back(tj);
      continue;
    }
    ++scored;
    Eigen::Vector3d off = cross - *hole;
    off -= n * n.dot(off);
    const bool is_caught = off.norm() <= clearance;
    const double oracle = planning::minimumDuration(robot_model.limits(), cfg.robot.home, Eigen::Vector3d::Zero(), cross);
    const double slack = r.first_detection >= 0.0 ? tc - (r.first_detection + robot_model.commandLatency() + oracle)
                                                  : -1.0;
    const bool is_reachable = r.first_detection >= 0.0 && robot_model.reachable(cross) && slack >= 0.0;
    reachable += is_reachable;
    caught += is_caught;
    caught_reachable += is_caught && is_reachable;
    tj["scored"] = true;
    tj["reachable"] = is_reachable;
    tj["caught"] = is_caught;
    tj["miss_distance_mm"] = 1e3 * off.norm();
    tj["oracle_slack_s"] = slack;
    per_throw.push_back(tj);
  }
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double rate_reachable = reachable > 0 ? static_cast<double>(caught_reachable) / reachable : nan;
  if (scored > 0)
    ctx.log("caught %d of %d throws; %d of %d reachable: catch rate %.3f", caught, scored, caught_reachable, reachable,
            rate_reachable);
  nlohmann::json j;
  j["role"] = "world";
  j["rig_hash"] = detail::hex(ctx.rig_hash);
  j["ticks"] = ticks;
  j["ticks_in_flight"] = truth_samples;
  j["tick_s"] = opt.tick_s;
  j["release_s"] = opt.release_s;
  j["episode_s"] = D;
  j["throws"] = opt.throws;
  j["throws_scored"] = scored;
  j["throws_unscored"] = unscored;
  j["reachable_throws"] = reachable;
  j["caught"] = caught;
  j["caught_reachable"] = caught_reachable;
  j["catch_rate_reachable"] = std::isfinite(rate_reachable) ? nlohmann::json(rate_reachable) : nlohmann::json(nullptr);
  j["catch_rate_all"] = scored > 0 ? nlohmann::json(static_cast<double>(caught) / scored) : nlohmann::json(nullptr);
  j["per_throw"] = per_throw;
  // The first throw's crossing, as before sessions of several throws.
  const sim::FlightState cross = truths[0].state(truths[0].crossingTime());
  j["crossing_time_s"] = truths[0].crossingTime();
  j["crossing_point_m"] = {cross.p.x(), cross.p.y(), cross.p.z()};
  j["interrupted"] = interrupted;
  j["wall_s"] = ctx.wallSeconds();
  return detail::finish(opt, j);
}

}  // namespace viewline::nodes
