#pragma once
// Scores the vision detectors against the ground truth of module sim's rendered images.
// Shared by tests/detection (assertions) and bench/vision/vision_figures (the printed tables).
// Header-only on purpose: two small consumers.

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "viewline/core/frames.h"
#include "viewline/sim/rig.h"
#include "viewline/sim/worlds.h"
#include "viewline/vision/apriltag_detector.h"
#include "viewline/vision/ball_detector.h"
#include "viewline/vision/table_detector.h"

namespace viewline::detection_scoring {

struct Score {
  int frames = 0;         ///< frames where the object was fully in view
  int detected = 0;       ///< of those, with a measurement
  int wrong = 0;          ///< measurements farther than max(gross, 3 sigma reported) from the truth
  double sq_error = 0.0;  ///< sum of squared errors of the detections
  double rate() const { return frames ? static_cast<double>(detected) / frames : 0.0; }
  double rms() const { return detected ? std::sqrt(sq_error / detected) : std::nan(""); }
};

// ---------------------------------------------------------------------------------------------
// Ball at 656x480 ([L]'s cameras): a 5 cm orange ball circling in front of a textured room.

inline core::Camera ballCamera() {
  core::Camera cam;
  cam.name = "ball656";
  cam.width = 656;
  cam.height = 480;
  cam.intrinsics = core::intrinsicsFromFov(core::deg2rad(60.0), 656, 480);
  cam.c_M_w = core::lookAt({0.0, -1.0, 1.2}, {0.0, 3.0, 1.1}, {0.0, 0.0, 1.0});
  return cam;
}

/// Ball centre at time t: a circle of radius 0.3 m at 1.5 m from the camera, 0.9 m/s.
inline Eigen::Vector3d ballPath(double t) {
  return {0.3 * std::cos(3.0 * t), 0.5, 1.15 + 0.2 * std::sin(3.0 * t)};
}

inline vision::BallDetectorConfig orangeBall() {
  vision::BallDetectorConfig cfg;
  cfg.hsv = vision::ColorRange{2, 24, 120, 255, 50, 255};
  return cfg;
}

/// Renders `n` frames at 50 Hz with `effects` (and `clutter` distractors of the ball's colour)
/// and scores BallDetector (with prediction from the previous detection) against the projection
/// of the sphere centre. `gross` (px): errors beyond count as wrong detections.
inline Score scoreBall(const sim::ImagingEffects& effects, int clutter, int n, std::uint64_t seed,
                       double gross = 3.0) {
  core::Rng rng = core::makeRng(seed);
  sim::RoomParams room;
  sim::Scene scene = sim::makeRoom(room, rng);
  if (clutter > 0) {
    sim::ClutterSettings c;
    c.count = clutter;
    c.min_w = {-0.8, 0.2, 0.7};
    c.max_w = {0.8, 1.5, 1.6};
    c.radius_min = 0.008;
    c.radius_max = 0.02;
    c.colour_bgr = {0.08, 0.45, 0.95};
    sim::addClutter(scene, c, rng);
  }
  const Eigen::Vector3d ball_albedo(0.08, 0.45, 0.95);
  sim::SceneWorld world(std::move(scene), [&](double t, std::vector<sim::Primitive>& out) {
    out.push_back(sim::makeSphere("ball", ballPath(t), 0.025, ball_albedo));
  });
  sim::SimCamera sc;
  sc.camera = ballCamera();
  sc.effects = effects;
  std::vector<sim::SimCamera> cams{sc};
  sim::CameraRig rig(cams, rng);
  vision::BallDetector det(orangeBall(), ballCamera());
  Score s;
  std::optional<Eigen::Vector2d> predicted;
  rig.run(world, 0.0, n / 50.0, [&](sim::Frame&& f) {
    const sim::ObjectTruth* truth = f.find("ball");
    if (!truth || !truth->in_image || !f.camera.inImage(truth->center_px, 15.0)) return;
    ++s.frames;
    const auto r = det.detect(f.image, f.stamp, predicted);
    if (!r) {
      predicted.reset();
      return;
    }
    predicted = r->pixel;
    const double e = (r->pixel - truth->center_px).norm();
    // Wrong = farther than `gross` and than 3 sigma of the detector's own covariance (a
    // degraded measurement with an honest covariance is not a silent wrong value).
    const double sigma = std::sqrt(r->pixel_covariance.eigenvalues().real().maxCoeff());
    if (e > std::max(gross, 3.0 * sigma)) {
      ++s.wrong;
      return;
    }
    ++s.detected;
    s.sq_error += e * e;
  });
  return s;
}

// ---------------------------------------------------------------------------------------------
// [M]'s table scene at 320x240, 90° field of view.

inline core::Camera tableCamera() {
  core::Camera cam;
  cam.name = "table320";
  cam.width = 320;
  cam.height = 240;
  cam.intrinsics = core::intrinsicsFromFov(core::deg2rad(90.0), 320, 240);
  // The table stands 0.75 m above the floor (its untilted frame: kTableHeight up).
  cam.c_M_w = core::lookAt({0.0, -0.32, 0.40 + 0.75}, {0.0, 0.0, 0.75}, {0.0, 0.0, 1.0});
  return cam;
}

struct TableScores {
  Score rotation;        ///< table rotation error, rad
  Score translation;     ///< table translation error, m
  Score ball_known;      ///< ball centre on the table, known radius, m
  Score ball_unknown;    ///< same, unknown radius
  Score tag_rotation;    ///< AprilTag table pose rotation error, rad
  Score tag_translation; ///< m
};

/// The table tilts along a Lissajous command (±2.3°, ±2°) while the ball rolls; `n` frames at 50 Hz.
/// `refine` = false: [M]'s steps exactly; `outline`: the ball outline of the refined detector.
inline TableScores scoreTable(int n, std::uint64_t seed, bool refine = true,
                              vision::TableDetectorConfig::BallOutline outline =
                                  vision::TableDetectorConfig::BallOutline::SphereCone) {
  core::Rng rng = core::makeRng(seed);
  sim::TiltTableParams params;
  params.w_M_base.translation() = Eigen::Vector3d(0.0, 0.0, 0.75);  // on a stand, above the floor
  sim::TiltTable table(params, sim::TiltTableState{0.0, {0.0, 0.0}, {0.05, -0.04}, {0.0, 0.0}});
  sim::RoomParams room;
  sim::TableAppearance look;
  look.tags = true;
  sim::TableWorld world(table, sim::makeRoom(room, rng), look);
  const core::Camera cam = tableCamera();
  vision::TableDetectorConfig cfg;
  cfg.refine = refine;
  cfg.ball_outline = outline;
  cfg.border_height_m = look.border_height;  // the sim's raised black borders
  vision::TableDetector det(cam, cfg);
  std::vector<vision::TagOnTable> layout;
  // vpDetectorAprilTag's tag frame (z out of the tag), not the simulator's (z into the table).
  for (int i = 0; i < 4; ++i) layout.push_back({look.first_tag_id + i, look.tag_size, world.table_M_vispTag(i)});
  vision::AprilTagTableDetector tags(cam, layout);
  sim::Renderer renderer;
  TableScores s;
  for (int k = 0; k < n; ++k) {
    const double t = 0.02 * k;
    table.command(t, Eigen::Vector2d(0.04 * std::sin(2.5 * t), 0.035 * std::sin(2.0 * t + 0.5)));
    table.advanceTo(t);
    std::vector<sim::ObjectTruth> truth;
    const cv::Mat img = renderer.render(world, cam, sim::ExposureSpec{t, 0.0, 1}, &truth);
    // Truth: the physics' table frame (surface centre, z along the normal) at the capture time.
    const Eigen::Isometry3d c_M_t = cam.c_M_w * table.tablePose(table.state().tilt);
    const Eigen::Vector3d ball_t(table.state().p.x(), table.state().p.y(), params.ball_radius);
    if (k == 0) det.setPrior(c_M_t);  // the square's quarter-turn symmetry, once
    const auto scene = det.detect(img, t);
    ++s.rotation.frames;
    ++s.translation.frames;
    ++s.ball_known.frames;
    ++s.ball_unknown.frames;
    if (scene.table) {
      const Eigen::Isometry3d est = vision::turnTableFrame(scene.table->c_M_t, vision::yawQuarterTurnsTo(scene.table->c_M_t, c_M_t));
      const double er = core::rotationAngle(est.linear(), c_M_t.linear());
      const double et = (est.translation() - c_M_t.translation()).norm();
      ++s.rotation.detected, s.rotation.sq_error += er * er;
      ++s.translation.detected, s.translation.sq_error += et * et;
      if (scene.ball) {
        const int q = vision::yawQuarterTurnsTo(scene.table->c_M_t, c_M_t);
        const Eigen::Matrix3d Rq = core::rotation(Eigen::Vector3d::UnitZ(), q * 0.5 * core::kPi);
        const Eigen::Vector3d pk = Rq.transpose() * scene.ball->known_radius.p_t;
        ++s.ball_known.detected, s.ball_known.sq_error += (pk - ball_t).squaredNorm();
        if (scene.ball->unknown_radius) {
          const Eigen::Vector3d pu = Rq.transpose() * scene.ball->unknown_radius->p_t;
          ++s.ball_unknown.detected, s.ball_unknown.sq_error += (pu - ball_t).squaredNorm();
        }
      }
    }
    ++s.tag_rotation.frames;
    ++s.tag_translation.frames;
    const auto tp = tags.detect(img, t);
    if (tp) {
      const double er = core::rotationAngle(tp->c_M_t.linear(), c_M_t.linear());
      const double et = (tp->c_M_t.translation() - c_M_t.translation()).norm();
      ++s.tag_rotation.detected, s.tag_rotation.sq_error += er * er;
      ++s.tag_translation.detected, s.tag_translation.sq_error += et * et;
    }
  }
  return s;
}

// ---------------------------------------------------------------------------------------------
// Robustness table: the ball detector under each imaging effect at three strengths.

struct EffectCase {
  std::string effect;
  std::string strength;
  sim::ImagingEffects effects;
  int clutter = 0;
};

inline std::vector<EffectCase> robustnessCases() {
  std::vector<EffectCase> out;
  out.push_back({"none", "-", {}, 0});
  for (double sigma : {5.0, 15.0, 30.0}) {
    EffectCase c{"sensor noise", "sigma " + std::to_string(static_cast<int>(sigma)), {}, 0};
    c.effects.noise.sigma = sigma;
    out.push_back(c);
  }
  for (double ms : {5.0, 10.0, 20.0}) {
    EffectCase c{"motion blur", "exposure " + std::to_string(static_cast<int>(ms)) + " ms", {}, 0};
    c.effects.blur.exposure = ms * 1e-3;
    c.effects.blur.samples = 7;
    out.push_back(c);
  }
  const std::vector<std::pair<std::string, Eigen::Vector3d>> light{
      {"gain 0.6", Eigen::Vector3d(0.6, 0.6, 0.6)},
      {"gain 1.4", Eigen::Vector3d(1.4, 1.4, 1.4)},
      {"white balance (1.3, 1, 0.7)", Eigen::Vector3d(1.3, 1.0, 0.7)}};
  for (const auto& [name, wb] : light) {
    EffectCase c{"illumination", name, {}, 0};
    c.effects.illumination.white_balance_bgr = wb;
    out.push_back(c);
  }
  for (double f : {0.2, 0.4, 0.6}) {
    EffectCase c{"occlusion", "fraction " + std::to_string(f).substr(0, 3), {}, 0};
    c.effects.occlusion.target = "ball";
    c.effects.occlusion.fraction = f;
    out.push_back(c);
  }
  for (int count : {5, 15, 40}) out.push_back({"clutter", std::to_string(count) + " blobs", {}, count});
  return out;
}

}  // namespace viewline::detection_scoring
