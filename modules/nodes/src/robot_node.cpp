#include "node_common.h"
#include "viewline/nodes/simulation.h"
#include "viewline/robots/cartesian_robot.h"

namespace viewline::nodes {

using detail::NodeContext;

nlohmann::json runRobotNode(const scenarios::BallCatchingConfig& cfg, const NodeOptions& opt) {
  NodeContext ctx(opt, "robot", "robot", rigHash(cfg));
  robots::SimulatedCartesianRobot robot(cfg.robot);
  robot.reset(0.0);
  dds::Reader<ClockMsg> clock_r(ctx.participant, ctx.clock_topic, dds::Qos::state(4));
  dds::Reader<SetPointMsg> sp_r(ctx.participant, ctx.setpoint_topic, dds::Qos::setpoints(opt.setpoint_deadline_s));
  dds::Writer<RobotStateMsg> state_w(ctx.participant, ctx.robot_topic, dds::Qos::state(16));
  dds::Reader<EpisodeMsg> episode_r(ctx.participant, ctx.episode_topic, dds::Qos::health());
  dds::WaitSet ws(ctx.participant);
  ws.attachData(clock_r);
  ws.attachData(sp_r);
  ws.attachData(episode_r);
  ws.attachData(ctx.health_reader);
  ws.attachStatus(sp_r, DDS_REQUESTED_DEADLINE_MISSED_STATUS);
  ctx.publishHealth(HealthStatus::Running, robot.name(), 0.0);
  ctx.log("%s, set-point deadline %.3f s", robot.name().c_str(), opt.setpoint_deadline_s);

  detail::SimClock clock(opt.realtime);
  std::uint64_t received = 0, states = 0;
  bool halted = false;
  double last_cmd_t = 0.0, last_sp_wall = 0.0;
  nlohmann::json halts = nlohmann::json::array();
  const std::string world_frame = "world";
  int episodes = 1;
  while (!ctx.shouldStop()) {
    ws.wait(0.01);
    ctx.takeHealth();
    // A new throw of the session: back at home from the episode's start (the in-process loop
    // starts each throw there); set points older than the start are dropped.
    episode_r.take([&](const EpisodeMsg& e, const dds_sample_info_t&) {
      if (e.index == 0) return;  // the node's start
      const double t0 = fromTimeMsg(e.header.stamp);
      robot.reset(t0);
      last_cmd_t = t0;
      halted = false;
      ++episodes;
    });
    sp_r.take([&](const SetPointMsg& m, const dds_sample_info_t&) {
      const double t = fromTimeMsg(m.header.stamp);
      if (t < last_cmd_t) return;  // older than the halt (or a duplicate): the robot does not go back
      if (halted) {
        ctx.log("set points again at t = %.3f s: resuming", t);
        halted = false;
      }
      robot.command({t, Eigen::Vector3d(m.position[0], m.position[1], m.position[2]),
                     Eigen::Vector3d(m.velocity[0], m.velocity[1], m.velocity[2])});
      last_cmd_t = t;
      last_sp_wall = ctx.wallSeconds();
      ++received;
    });
    // The reader's deadline (Qos::setpoints): the tracker went silent. Hold where the box is.
    if (sp_r.deadlinesMissed() > 0 && received > 0 && !halted) {
      halted = true;
      const double after = ctx.wallSeconds() - last_sp_wall;
      const double t = std::max(clock.now(), last_cmd_t);
      robot.command({t, robot.read(t).p, Eigen::Vector3d::Zero()});
      last_cmd_t = t;
      ctx.log("HALT: no set point for %.3f s (deadline %.3f s) at t = %.3f s", after, opt.setpoint_deadline_s, t);
      halts.push_back({{"t", t}, {"after_last_setpoint_s", after}, {"wall_s", ctx.wallSeconds()}});
    }
    clock_r.take([&](const ClockMsg& m, const dds_sample_info_t&) {
      clock.onClock(fromTimeMsg(m.clock));
      const robots::CartesianState s = robot.read(clock.latest());
      RobotStateMsg r{};
      r.header.stamp = m.clock;
      r.header.frame_id = messageString(world_frame);
      for (int k = 0; k < 3; ++k) {
        r.position[k] = s.p(k);
        r.velocity[k] = s.v(k);
      }
      r.halted = halted;
      r.setpoints = received;
      state_w.write(r);
      ++states;
    });
    if (ctx.worldFinished()) break;
  }
  nlohmann::json j;
  j["role"] = "robot";
  j["rig_hash"] = detail::hex(ctx.rig_hash);
  j["setpoints"] = received;
  j["states"] = states;
  j["halted"] = halted;
  j["episodes"] = episodes;
  j["acceleration_violations"] = robot.accelerationViolations();
  j["halts"] = halts;
  j["deadline_s"] = opt.setpoint_deadline_s;
  j["velocity_violations"] = robot.velocityViolations();
  j["wall_s"] = ctx.wallSeconds();
  return detail::finish(opt, j);
}

}  // namespace viewline::nodes
