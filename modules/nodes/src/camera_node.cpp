#include <opencv2/core.hpp>
#include <thread>

#include "node_common.h"
#include "viewline/core/error.h"
#include "viewline/nodes/simulation.h"
#include "viewline/scenarios/ball_catching/world.h"
#include "viewline/sim/renderer.h"
#include "viewline/sim/worlds.h"
#include "viewline/vision/ball_detector.h"

namespace viewline::nodes {

using detail::NodeContext;

namespace {

// The camera's image as the in-process scenario renders it (its room, the box held at home, the
// ball at the true position; the true camera and its sensor noise) and the scenario's detector on
// it (window around the last detection). Motion blur is left out: one render per frame.
class RenderedCamera {
public:
  RenderedCamera(const scenarios::BallCatchingConfig& cfg, std::size_t index, std::uint64_t seed)
      : cfg_(cfg), camera_(cfg.cameras[index].renderCamera()), renderer_(cfg.render),
        detector_(cfg.detector, cfg.cameras[index].estimatorCamera()), noise_sigma_(cfg.cameras[index].noise_sigma),
        noise_rng_(core::makeRng(core::deriveSeed(seed, 0x300 + index))) {
    core::Rng room_rng = core::makeRng(core::deriveSeed(seed, 0xB0B));  // the session's room (runBallCatching)
    world_ = std::make_unique<sim::SceneWorld>(sim::makeRoom(cfg.room, room_rng), [this](double, std::vector<sim::Primitive>& out) {
      if (ball_) out.push_back(sim::makeSphere("ball", *ball_, cfg_.throws.body.reference_radius, cfg_.ball_albedo_bgr));
      if (cfg_.render_box) scenarios::appendBox(cfg_, scenarios::boxRotation(cfg_.box_normal), cfg_.robot.home, out);
    });
  }

  // Renders the frame at t with the ball at p (none: no ball) and detects it.
  std::optional<vision::BallMeasurement> frame(double t, double stamp, const std::optional<Eigen::Vector3d>& p) {
    ball_ = p;
    cv::Mat image = renderer_.render(*world_, camera_, sim::ExposureSpec{t, 0.0, 1});
    if (noise_sigma_ > 0.0) {
      cv::Mat noise(image.size(), CV_32FC3);
      cv::theRNG().state = noise_rng_();  // seeded: reproducible sensor noise
      cv::randn(noise, 0.0, noise_sigma_);
      cv::Mat f;
      image.convertTo(f, CV_32FC3);
      f += noise;
      f.convertTo(image, CV_8UC3);
    }
    auto det = detector_.detect(image, stamp, last_);
    if (!det.ok()) {
      last_.reset();
      return std::nullopt;
    }
    last_ = det.value().pixel;
    return det.value();
  }

private:
  const scenarios::BallCatchingConfig& cfg_;
  core::Camera camera_;
  sim::Renderer renderer_;
  vision::BallDetector detector_;
  double noise_sigma_;
  core::Rng noise_rng_;
  std::unique_ptr<sim::SceneWorld> world_;
  std::optional<Eigen::Vector3d> ball_;
  std::optional<Eigen::Vector2d> last_;
};

}  // namespace

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
  std::unique_ptr<RenderedCamera> rendered;
  if (opt.render) rendered = std::make_unique<RenderedCamera>(cfg, opt.camera, opt.seed);
  const std::string frame_id = gen.name();
  ctx.publishHealth(HealthStatus::Running, "camera " + frame_id, 0.0);
  ctx.log("camera %s at %.1f Hz, %s, rig %s", frame_id.c_str(), cfg.throwRate(opt.camera),
          opt.render ? "rendered images + ball detector" : "generator", detail::hex(ctx.rig_hash).c_str());

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
      std::optional<GeneratedFrame> f = gen.onTick(t, p);  // the capture schedule, and the generator's pixel
      if (!f) return;
      Eigen::Matrix2d cov = f->sigma_px * f->sigma_px * Eigen::Matrix2d::Identity();
      if (rendered) {
        const auto det = rendered->frame(t, f->stamp, p);
        f->pixel.reset();
        if (det) {
          f->pixel = det->pixel;
          // The detector's std as measured against the truth (detector.sigma_px), else the blob's
          // own covariance: what the in-process loop tells its tracker.
          cov = cfg.sigma_px > 0.0 ? Eigen::Matrix2d(cfg.sigma_px * cfg.sigma_px * Eigen::Matrix2d::Identity())
                                   : det->pixel_covariance;
        }
      }
      DetectionMsg d{};
      d.header.stamp = toTimeMsg(f->stamp);
      d.header.frame_id = messageString(frame_id);
      d.camera = static_cast<std::uint32_t>(opt.camera);
      d.frame_number = f->frame_number;
      d.detected = f->pixel.has_value();
      if (f->pixel) {
        d.pixel[0] = f->pixel->x();
        d.pixel[1] = f->pixel->y();
        for (int k = 0; k < 4; ++k) d.covariance[k] = cov(k / 2, k % 2);
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
