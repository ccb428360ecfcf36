#include <thread>

#include "node_common.h"
#include "viewline/core/error.h"
#include "viewline/nodes/simulation.h"

namespace viewline::nodes {

using detail::NodeContext;

nlohmann::json runCameraNode(const scenarios::BallCatchingConfig& cfg, const NodeOptions& opt) {
  if (opt.camera >= cfg.activeCameras())
    throw core::InvalidInput("camera: --camera " + std::to_string(opt.camera) + " but the config uses " +
                             std::to_string(cfg.activeCameras()) + " cameras (camera_count)");
  NodeContext ctx(opt, "camera" + std::to_string(opt.camera), "camera", rigHash(cfg));
  dds::Reader<ClockMsg> clock_r(ctx.participant, ctx.clock_topic, dds::Qos::state(1));  // the world counts it
  dds::Reader<ObjectTruthMsg> truth_r(ctx.participant, ctx.truth_topic, dds::Qos::state(256));
  dds::Writer<DetectionMsg> det_w(ctx.participant, ctx.detection_topic, dds::Qos::cameraWriter());
  dds::WaitSet ws(ctx.participant);
  ws.attachData(truth_r);
  ws.attachData(ctx.health_reader);
  DetectionGenerator gen(cfg, opt.camera, opt.seed, opt.pixel_sigma, opt.clock_offset_s);
  const std::string frame_id = gen.name();
  ctx.publishHealth(HealthStatus::Running, "camera " + frame_id, 0.0);
  ctx.log("camera %s at %.1f Hz, rig %s", frame_id.c_str(), cfg.throwRate(opt.camera), detail::hex(ctx.rig_hash).c_str());

  std::uint64_t frames = 0, detections = 0;
  double t_last = 0.0;
  while (!ctx.shouldStop()) {
    ws.wait(0.05);
    ctx.takeHealth();
    for (const auto& [name, peer] : ctx.peers()) {
      if (peer.role != "tracker" || peer.rig_hash == ctx.rig_hash) continue;
      const std::string msg = "rig hash " + detail::hex(ctx.rig_hash) + " differs from the tracker's " +
                              detail::hex(peer.rig_hash) + ": start every node with the same rig and camera_count";
      ctx.publishHealth(HealthStatus::Refused, msg, t_last);
      std::this_thread::sleep_for(std::chrono::milliseconds(300));  // the tracker hears why before the node goes
      throw core::Error("camera " + std::to_string(opt.camera) + ": " + msg);
    }
    truth_r.take([&](const ObjectTruthMsg& m, const dds_sample_info_t&) {
      const double t = fromTimeMsg(m.header.stamp);
      t_last = t;
      std::optional<Eigen::Vector3d> p;
      if (m.in_flight) p = Eigen::Vector3d(m.position[0], m.position[1], m.position[2]);
      const std::optional<GeneratedFrame> f = gen.onTick(t, p);
      if (!f) return;
      DetectionMsg d{};
      d.header.stamp = toTimeMsg(f->stamp);
      d.header.frame_id = messageString(frame_id);
      d.camera = static_cast<std::uint32_t>(opt.camera);
      d.frame_number = f->frame_number;
      d.detected = f->pixel.has_value();
      if (f->pixel) {
        d.pixel[0] = f->pixel->x();
        d.pixel[1] = f->pixel->y();
        d.covariance[0] = d.covariance[3] = f->sigma_px * f->sigma_px;
        d.quality = 1.0;
        ++detections;
      }
      det_w.write(d);
      ++frames;
    });
    if (ctx.worldFinished()) break;
  }
  ctx.log("%llu frames, %llu with the ball", static_cast<unsigned long long>(frames),
          static_cast<unsigned long long>(detections));
  nlohmann::json j;
  j["role"] = "camera";
  j["camera"] = opt.camera;
  j["name"] = frame_id;
  j["rig_hash"] = detail::hex(ctx.rig_hash);
  j["frames"] = frames;
  j["detections"] = detections;
  j["wall_s"] = ctx.wallSeconds();
  j["cpu_s"] = detail::processCpuSeconds();
  return detail::finish(opt, j);
}

}  // namespace viewline::nodes
