#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <memory>
#include <set>

#include "node_common.h"
#include "viewline/core/error.h"
#include "viewline/io/files.h"
#include "viewline/nodes/simulation.h"
#include "viewline/planning/catch_planner.h"
#include "viewline/core/random.h"
#include "viewline/scenarios/ball_catching/planner_input.h"
#include "viewline/scenarios/ball_catching/registration.h"
#include "viewline/sim/worlds.h"
#include "viewline/robots/cartesian_robot.h"
#include "viewline/tracking/tracker.h"

namespace viewline::nodes {

using detail::NodeContext;

namespace {

// What the tracker saw of one camera.
struct CameraDelivery {
  std::string name;
  std::uint64_t received = 0, detected = 0, fused = 0, refused = 0;
  std::uint64_t first_frame = 0, last_frame = 0;
  std::uint64_t earlier_span = 0;  // frames the camera numbered before it restarted (its count starts again)
  bool any = false, alive = true;
  std::vector<double> delays;  // capture stamp -> tracker update, s of simulated time
};

}  // namespace

nlohmann::json runTrackerNode(const scenarios::BallCatchingConfig& config, const NodeOptions& opt) {
  NodeContext ctx(opt, "tracker", "tracker", rigHash(config));
  // The estimators as the ball-catching session builds them (loop.cpp: runBallCatching, ThrowLoop):
  // the calibrated cameras registered to the robot first (registration.enabled: the session step
  // that shows the robot's marker to the cameras, simulated here with the session's room and seed,
  // as on a real rig one would register before starting the nodes), the scenario's tracker config,
  // the planner asking the robot model for its limits.
  scenarios::BallCatchingConfig cfg = config;
  nlohmann::json registration_j = nullptr;
  if (cfg.registration.enabled) {
    core::Rng room_rng = core::makeRng(core::deriveSeed(opt.seed, 0xB0B));
    const scenarios::RegistrationResult r =
        scenarios::registerCamerasToRobot(cfg, sim::makeRoom(cfg.room, room_rng), core::deriveSeed(opt.seed, 0x4E6));
    ctx.log("%d cameras registered to the robot: marker reprojection %.3f px -> %.3f px", r.cameras_registered,
            r.reprojection_px_before, r.reprojection_px_after);
    registration_j = {{"cameras_registered", r.cameras_registered},
                      {"reprojection_px_before", r.reprojection_px_before},
                      {"reprojection_px_after", r.reprojection_px_after}};
  }
  std::vector<core::Camera> cams;
  for (std::size_t i = 0; i < cfg.activeCameras(); ++i) cams.push_back(cfg.cameras[i].estimatorCamera());
  auto tracker_ptr = std::make_unique<tracking::ViewlineTracker>(cams, cfg.tracker);
  const robots::SimulatedCartesianRobot robot_model(cfg.robot);
  planning::CatchPlanner planner(cfg.plannerConfig(), robot_model);
  planner.reset(0.0, cfg.robot.home);
  // What the planner predicts from: the in-process loop's rule (scenarios/ball_catching/planner_input.h).
  scenarios::PlannerInput planner_input(cfg, cams);

  dds::Reader<ClockMsg> clock_r(ctx.participant, ctx.clock_topic, dds::Qos::state(4));
  dds::Reader<DetectionMsg> det_r(ctx.participant, ctx.detection_topic, dds::Qos::detections(256));
  dds::Writer<TrackStateMsg> track_w(ctx.participant, ctx.track_topic, dds::Qos::state(16));
  dds::Writer<SetPointMsg> sp_w(ctx.participant, ctx.setpoint_topic, dds::Qos::setpoints(opt.setpoint_deadline_s));
  dds::Reader<EpisodeMsg> episode_r(ctx.participant, ctx.episode_topic, dds::Qos::health());
  dds::WaitSet ws(ctx.participant);
  ws.attachData(clock_r);
  ws.attachData(det_r);
  ws.attachData(episode_r);
  ws.attachData(ctx.health_reader);
  ws.attachStatus(det_r, DDS_LIVELINESS_CHANGED_STATUS);
  ctx.publishHealth(HealthStatus::Running, "tracking " + std::to_string(cams.size()) + " cameras", 0.0);
  ctx.log("%zu cameras, rig %s", cams.size(), detail::hex(ctx.rig_hash).c_str());

  detail::SimClock clock(opt.realtime);
  std::vector<CameraDelivery> cam(cams.size());
  for (std::size_t i = 0; i < cams.size(); ++i) cam[i].name = cams[i].name;
  std::map<dds_instance_handle_t, std::size_t> writer_camera;  // detection writer -> camera index
  std::set<std::size_t> refused_rig;
  nlohmann::json left = nlohmann::json::array(), rejoined = nlohmann::json::array(), foreign = nlohmann::json::array();
  std::uint64_t next_id = 1, track_msgs = 0, setpoints = 0, unknown_camera = 0;
  double next_control = 0.0;
  const std::string world_frame = "world";

  // A session of throws (the world's rt/viewline/episode): from each episode's start the tracker,
  // the fit and the plan start afresh, as the in-process loop starts each throw.
  std::optional<double> pending_episode;
  int episodes = 0;
  auto startEpisodeBy = [&](double t) {
    if (!pending_episode || t < *pending_episode) return;
    tracker_ptr = std::make_unique<tracking::ViewlineTracker>(cams, cfg.tracker);
    planner.reset(*pending_episode, cfg.robot.home);
    planner_input.reset();
    pending_episode.reset();
    ++episodes;
  };

  auto publishTrack = [&] {
    const tracking::ViewlineTracker& tracker = *tracker_ptr;
    const estimation::StateEstimate& s = tracker.state();
    TrackStateMsg m{};
    m.header.stamp = toTimeMsg(s.t());
    m.header.frame_id = messageString(world_frame);
    m.status = static_cast<std::uint8_t>(tracker.initialised() ? TrackStatus::Tracking : TrackStatus::None);
    for (int k = 0; k < 6; ++k) m.state[k] = s.x()(k);
    packCovarianceFactor(s.P().topLeftCorner<6, 6>(), m.covariance_factor);
    m.fused = static_cast<std::uint32_t>(tracker.trackState().fused_in_track);
    track_w.write(m);
    ++track_msgs;
  };

  // Optional per-detection log (opt.track_log_path), a row as each detection is fused; closed (and
  // its errors reported) when the node ends, also on SIGINT/SIGTERM.
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> track_log(nullptr, &std::fclose);
  if (!opt.track_log_path.empty()) {
    track_log.reset(std::fopen(opt.track_log_path.c_str(), "w"));
    if (!track_log) io::throwFileError("tracker: track log " + opt.track_log_path, errno);
    std::fprintf(track_log.get(), "t,camera,stamp,delay_s,x,y,z,sigma_m\n");
  }
  auto logTrack = [&](std::size_t c, double t_update, double stamp) {
    if (!track_log) return;
    const estimation::StateEstimate& s = tracker_ptr->state();
    const double sigma = std::sqrt(s.P().topLeftCorner<3, 3>().trace());
    if (std::fprintf(track_log.get(), "%.6f,%zu,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f\n", t_update, c, stamp, t_update - stamp,
                     s.x()(0), s.x()(1), s.x()(2), sigma) < 0)
      io::throwFileError("tracker: track log " + opt.track_log_path, errno);
  };

  bool draining = false;
  while (!ctx.shouldStop()) {
    ws.wait(0.02);
    for (const std::string& name : ctx.takeHealth()) {
      const detail::PeerHealth& p = ctx.peers().at(name);
      if (p.role != "camera" || p.rig_hash == ctx.rig_hash) continue;
      // Camera node names are "camera<i>": refuse that index's detections.
      const std::size_t i = std::stoul(name.substr(6));
      if (refused_rig.insert(i).second) {
        ctx.log("REFUSED %s: its rig hash %s differs from the tracker's %s; its detections are dropped",
                name.c_str(), detail::hex(p.rig_hash).c_str(), detail::hex(ctx.rig_hash).c_str());
        foreign.push_back({{"camera", name}, {"rig_hash", detail::hex(p.rig_hash)}});
      }
    }
    clock_r.take([&](const ClockMsg& m, const dds_sample_info_t&) { clock.onClock(fromTimeMsg(m.clock)); });
    episode_r.take([&](const EpisodeMsg& e, const dds_sample_info_t&) {
      if (e.index > 0) pending_episode = fromTimeMsg(e.header.stamp);  // episode 0 is the node's start
    });
    // Set points every control period of simulated time, up to the newest tick, before the
    // detections that arrived: an update then plans from a time no earlier than the last set
    // point sent (the in-process order: estimates reach the planner, then the tick's set point).
    while (clock.started() && next_control <= clock.latest()) {
      startEpisodeBy(next_control);
      const robots::CartesianState sp = planner.setpoint(next_control);
      SetPointMsg m{};
      m.header.stamp = toTimeMsg(next_control);
      m.header.frame_id = messageString(world_frame);
      for (int k = 0; k < 3; ++k) {
        m.position[k] = sp.p(k);
        m.velocity[k] = sp.v(k);
      }
      if (const auto& target = planner.target()) {
        m.has_target = true;
        m.target_time = target->t;
        for (int k = 0; k < 3; ++k) m.target_position[k] = target->p(k);
      }
      sp_w.write(m);
      ++setpoints;
      next_control += cfg.control_period;
    }
    det_r.take([&](const DetectionMsg& d, const dds_sample_info_t& info) {
      if (d.camera >= cam.size()) {
        ++unknown_camera;
        return;
      }
      const std::size_t c = d.camera;
      CameraDelivery& cd = cam[c];
      const bool new_writer = writer_camera.emplace(info.publication_handle, c).second;
      if (refused_rig.count(c)) {
        ++cd.refused;
        return;
      }
      if (new_writer && !cd.alive) {
        // The camera left and a new writer for it speaks: the node was restarted. Its frame
        // numbers start again, so the frames it numbered before count apart.
        cd.alive = true;
        if (cd.any) cd.earlier_span += cd.last_frame - cd.first_frame + 1;
        cd.any = false;
        ctx.log("camera %s rejoined at t = %.3f s", cd.name.c_str(), clock.now());
        rejoined.push_back({{"camera", cd.name}, {"t", clock.now()}, {"wall_s", ctx.wallSeconds()}});
      }
      ++cd.received;
      if (!cd.any || d.frame_number < cd.first_frame) cd.first_frame = d.frame_number;
      cd.last_frame = cd.any ? std::max(cd.last_frame, d.frame_number) : d.frame_number;
      cd.any = true;
      const double stamp = fromTimeMsg(d.header.stamp);
      cd.delays.push_back(clock.now() - stamp);
      if (!d.detected) return;
      startEpisodeBy(stamp);
      tracking::ViewlineTracker& tracker = *tracker_ptr;
      ++cd.detected;
      const double sigma = std::max(cfg.sigma_px_floor, std::sqrt(0.5 * (d.covariance[0] + d.covariance[3])));
      const tracking::ImageMeasurement m{next_id++, c, stamp, Eigen::Vector2d(d.pixel[0], d.pixel[1]), sigma};
      if (tracker.submit(m) != tracking::Refusal::None) return;
      const auto o = tracker.outcome(m.id);
      if (!o || o->fate != tracking::Fate::Fused || !tracker.initialised()) return;
      ++cd.fused;
      logTrack(c, clock.now(), stamp);
      publishTrack();
      // Planned from now, but not before the last set point sent nor after the next one (the
      // plan's set points stay continuous in time).
      const double t_update = std::clamp(std::max(clock.now(), stamp), next_control - cfg.control_period, next_control);
      planner.update(t_update, planner_input.after(m, tracker));
    });
    // A writer that lost its liveliness (process killed, hung, cut off) turns "not alive"; one
    // deleted cleanly (its node ended) is unmatched instead, so only the first is a camera lost.
    const dds::LivelinessStatus live = det_r.liveliness();
    if (live.alive_change < 0) {
      const auto it = writer_camera.find(live.last_writer);
      const std::string who = it != writer_camera.end() ? cam[it->second].name : "unknown";
      if (it != writer_camera.end()) cam[it->second].alive = false;
      if (live.not_alive_change > 0) {
        ctx.log("camera %s left (liveliness lost, lease %.1f s) at t = %.3f s; going on with %d cameras", who.c_str(),
                dds::Qos::kCameraLeaseS, clock.now(), live.alive);
        left.push_back({{"camera", who}, {"t", clock.now()}, {"wall_s", ctx.wallSeconds()}, {"alive", live.alive}});
      } else {
        ctx.log("camera %s closed its writer at t = %.3f s", who.c_str(), clock.now());
      }
    }
    if (draining) break;
    draining = ctx.worldFinished();  // one more pass takes what is still in flight
  }

  if (track_log && std::fclose(track_log.release()) != 0)
    io::throwFileError("tracker: track log " + opt.track_log_path, errno);

  nlohmann::json j;
  j["role"] = "tracker";
  j["rig_hash"] = detail::hex(ctx.rig_hash);
  const tracking::ViewlineTracker& tracker = *tracker_ptr;
  j["initialised"] = tracker.initialised();
  j["registration"] = registration_j;
  j["episodes"] = episodes + 1;
  const estimation::StateEstimate& s = tracker.state();
  if (s.x().size() >= 6) {  // empty before the first track
    j["t"] = s.t();
    j["x"] = std::vector<double>(s.x().data(), s.x().data() + 6);
    const Eigen::Matrix<double, 6, 6> P = s.P().topLeftCorner<6, 6>();
    j["P"] = std::vector<double>(P.data(), P.data() + 36);  // column-major = row-major (symmetric)
  }
  j["fused_in_track"] = tracker.trackState().fused_in_track;
  j["tracks_started"] = tracker.trackState().tracks_started;
  j["track_messages"] = track_msgs;
  j["setpoints"] = setpoints;
  j["unknown_camera"] = unknown_camera;
  j["cameras_left"] = left;
  j["cameras_rejoined"] = rejoined;
  j["cameras_refused"] = foreign;
  nlohmann::json cj = nlohmann::json::array();
  for (const CameraDelivery& cd : cam) {
    const std::uint64_t span = cd.earlier_span + (cd.any ? cd.last_frame - cd.first_frame + 1 : 0);
    // Apparent clock offset, the minimum filter of NTP: delay = transport − offset for a camera
    // whose clock runs `offset` ahead of the time base, so −min(delay) = offset − the smallest
    // transport delay (a slight underestimate of the offset).
    double offset = 0.0;
    if (!cd.delays.empty()) offset = -*std::min_element(cd.delays.begin(), cd.delays.end());
    cj.push_back({{"name", cd.name},
                  {"received", cd.received},
                  {"detected", cd.detected},
                  {"fused", cd.fused},
                  {"refused", cd.refused},
                  {"lost", span - std::min(span, cd.received)},
                  {"delay_p50_s", detail::quantile(cd.delays, 0.5)},
                  {"delay_p99_s", detail::quantile(cd.delays, 0.99)},
                  {"apparent_clock_offset_s", offset},
                  {"alive", cd.alive}});
    if (cd.received > 0)
      ctx.log("%s: %llu frames (%llu lost), delay p50 %.2f ms p99 %.2f ms, apparent clock offset %.2f ms", cd.name.c_str(),
              static_cast<unsigned long long>(cd.received), static_cast<unsigned long long>(span - std::min(span, cd.received)),
              1e3 * detail::quantile(cd.delays, 0.5), 1e3 * detail::quantile(cd.delays, 0.99), 1e3 * offset);
  }
  j["cameras"] = cj;
  j["wall_s"] = ctx.wallSeconds();
  j["cpu_s"] = detail::processCpuSeconds();
  return detail::finish(opt, j);
}

}  // namespace viewline::nodes
