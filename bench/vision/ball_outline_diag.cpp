// Diagnostic (not a figure): ball circle errors of each outline method against the exact
// projected sphere, on [M]'s scene as scored by detection_scoring::scoreTable.
//   ball_outline_diag [frames=100] [seed=2] [verbose] [frame to dump]
// Environment knobs for the sphere-cone parameters (evaluation only): RAYS, REACH, MARGIN,
// MAX_GAP, MAX_SIG; imaging effects NOISE (sigma) and EXPOSURE (s); TIMING=1 prints CPU times.
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "detection_scoring.h"
#include "viewline/sim/effects.h"

int main(int argc, char** argv) {
  using namespace viewline;
  cv::setNumThreads(1);
  const int n = argc > 1 ? std::atoi(argv[1]) : 100;
  const std::uint64_t seed = argc > 2 ? std::strtoull(argv[2], nullptr, 10) : 2;
  const bool verbose = argc > 3;
  core::Rng rng = core::makeRng(seed);
  sim::TiltTableParams params;
  params.w_M_base.translation() = Eigen::Vector3d(0.0, 0.0, 0.75);
  sim::TiltTable table(params, sim::TiltTableState{0.0, {0.0, 0.0}, {0.05, -0.04}, {0.0, 0.0}});
  sim::RoomParams room;
  sim::TableAppearance look;
  look.tags = true;
  sim::TableWorld world(table, sim::makeRoom(room, rng), look);
  const core::Camera cam = detection_scoring::tableCamera();
  struct Method { const char* name; vision::TableDetectorConfig cfg; double sq_rho = 0, sum_rho = 0, sq_c = 0, sq_true = 0, sq_est = 0; int n = 0, nest = 0; };
  std::vector<Method> methods(3);
  methods[0].name = "[M] minEnclosingCircle";
  methods[0].cfg.refine = false;
  methods[1].name = "greenness ellipse";
  methods[1].cfg.ball_outline = vision::TableDetectorConfig::BallOutline::GreennessEllipse;
  methods[2].name = "sphere cone (unmixing)";
  for (auto& m : methods) m.cfg.border_height_m = look.border_height;
  int fallbacks = 0, n_el = 0;
  double sq_el = 0.0, sq_cone = 0.0;
  if (const char* g = std::getenv("MARGIN")) methods[2].cfg.ball_outline_params.clean_margin_px = std::atof(g);
  if (const char* g = std::getenv("MAX_SIG")) methods[2].cfg.ball_outline_params.max_alpha_sigma_px = std::atof(g);
  if (const char* g = std::getenv("MAX_GAP")) methods[2].cfg.ball_outline_params.max_gap_deg = std::atof(g);
  if (const char* g = std::getenv("RAYS")) methods[2].cfg.ball_outline_params.rays = std::atoi(g);
  if (const char* g = std::getenv("REACH")) methods[2].cfg.ball_outline_params.reach_px = std::atof(g);
  std::vector<vision::TableDetector> dets;
  for (auto& m : methods) dets.emplace_back(cam, m.cfg);
  sim::Renderer renderer;
  const double exposure = std::getenv("EXPOSURE") ? std::atof(std::getenv("EXPOSURE")) : 0.0;
  std::optional<sim::NoisePool> noise;
  if (std::getenv("NOISE")) noise.emplace(sim::SensorNoise{std::atof(std::getenv("NOISE")), 1u << 21}, rng);
  for (int k = 0; k < n; ++k) {
    const double t = 0.02 * k;
    table.command(t, Eigen::Vector2d(0.04 * std::sin(2.5 * t), 0.035 * std::sin(2.0 * t + 0.5)));
    table.advanceTo(t);
    cv::Mat img = renderer.render(world, cam, sim::ExposureSpec{t, exposure, exposure > 0.0 ? 3 : 1}, nullptr);
    if (noise) noise->apply(img, rng);
    const Eigen::Isometry3d c_M_t = cam.c_M_w * table.tablePose(table.state().tilt);
    const Eigen::Vector3d ball_t(table.state().p.x(), table.state().p.y(), params.ball_radius);
    const Eigen::Vector3d p_c = c_M_t * ball_t;
    vision::SphereCone truth;
    truth.axis = p_c.normalized();
    truth.alpha = std::asin(params.ball_radius / p_c.norm());
    const vision::Circle tc = vision::circleFromSphereCone(cam, truth);
    if (verbose) std::printf("%3d ball_t (%.3f %.3f) rho %.3f:", k, ball_t.x(), ball_t.y(), tc.radius);
    std::optional<vision::Circle> prev;
    for (std::size_t i = 0; i < methods.size(); ++i) {
      if (k == 0) dets[i].setPrior(c_M_t);
      const auto scene = dets[i].detect(img, t);
      if (!scene.ball_circle) continue;
      if (i == 2 && prev && prev->radius == scene.ball_circle->radius) ++fallbacks;
      prev = scene.ball_circle;
      auto& m = methods[i];
      const double dr = scene.ball_circle->radius - tc.radius;
      m.sq_rho += dr * dr;
      m.sum_rho += dr;
      m.sq_c += (scene.ball_circle->center - tc.center).squaredNorm();
      const auto g = vision::ballOnTableKnownRadius(cam, *scene.ball_circle, c_M_t, params.ball_radius);
      m.sq_true += (g.p_t - ball_t).squaredNorm();
      ++m.n;
      if (verbose) std::printf("  %+.3f", dr);
      if (verbose && i == 1) {
        vision::BallOutlineParams bp = methods[2].cfg.ball_outline_params;
        bp.max_gap_deg = 360.0;
        const auto c1 = vision::refineBallBySphereCone(img, cam, *scene.ball_circle, bp);
        if (c1) {
          const auto cone = vision::fitSphereCone(cam, vision::ballOutlinePoints(img, *c1, bp), bp);
          const auto pts2 = vision::ballOutlinePoints(img, *c1, bp);
          if (pts2.size() >= 16) {
            std::vector<cv::Point2f> cvp;
            for (const auto& q : pts2) cvp.emplace_back(static_cast<float>(q.x()), static_cast<float>(q.y()));
            const cv::RotatedRect el = cv::fitEllipse(cvp);
            const double a = 0.5 * static_cast<double>(std::max(el.size.width, el.size.height));
            if (cone && cone->max_gap_rad < core::deg2rad(180.0) && cone->alpha_sigma_px < 0.015) {
              ++n_el; sq_el += std::pow(a - tc.radius, 2); sq_cone += std::pow(c1->radius - tc.radius, 2);
            }
          }
          if (cone) std::printf(" [gap %3.0f sig %.3f rms %.3f n %2d err %+.3f]", core::rad2deg(cone->max_gap_rad), cone->alpha_sigma_px, cone->rms_px, cone->inliers, c1->radius - tc.radius);
        }
      }
      if (scene.ball) {
        const int q = vision::yawQuarterTurnsTo(scene.table->c_M_t, c_M_t);
        const Eigen::Matrix3d Rq = core::rotation(Eigen::Vector3d::UnitZ(), q * 0.5 * core::kPi);
        m.sq_est += (Rq.transpose() * scene.ball->known_radius.p_t - ball_t).squaredNorm();
        ++m.nest;
      }
    }
    if (verbose) std::printf("\n");
    if (argc > 4 && k == std::atoi(argv[4])) {
      const auto sc = dets[1].detect(img, t);
      cv::imwrite("/tmp/vision2/frame.png", img);
      const auto pts = vision::ballOutlinePoints(img, *sc.ball_circle);
      for (const auto& p : pts) {
        const Eigen::Vector2d xy = cam.pixelToNormalized(p);
        const Eigen::Vector3d w = Eigen::Vector3d(xy.x(), xy.y(), 1.0).normalized();
        const double th = std::atan2(p.y() - sc.ball_circle->center.y(), p.x() - sc.ball_circle->center.x());
        std::printf("  pt %7.2f %7.2f  angle %6.1f deg  res vs truth %+.3f px\n", p.x(), p.y(), core::rad2deg(th),
                    cam.intrinsics.get_px() * (std::acos(w.dot(truth.axis)) - truth.alpha));
      }
      const auto cone = vision::fitSphereCone(cam, pts);
      if (cone) std::printf("  fit: inliers %d rms %.3f px\n", cone->inliers, cone->rms_px);
    }
  }
  std::printf("| method | radius bias px | radius RMS px | centre RMS px | known-r, true pose, mm | known-r, est. pose, mm (n) |\n|---|---|---|---|---|---|\n");
  for (const auto& m : methods)
    std::printf("| %s | %+.4f | %.4f | %.4f | %.2f | %.2f (%d) |\n", m.name, m.sum_rho / m.n, std::sqrt(m.sq_rho / m.n),
                std::sqrt(m.sq_c / m.n), 1e3 * std::sqrt(m.sq_true / m.n), 1e3 * std::sqrt(m.sq_est / std::max(1, m.nest)), m.nest);
  if (std::getenv("TIMING")) {
    // CPU time per call on the last frames (same image repeated), single thread.
    std::vector<cv::Mat> imgs;
    for (int k = 0; k < 40; ++k) {
      const double t = 0.02 * (n + k);
      table.command(t, Eigen::Vector2d(0.04 * std::sin(2.5 * t), 0.035 * std::sin(2.0 * t + 0.5)));
      table.advanceTo(t);
      imgs.push_back(renderer.render(world, cam, sim::ExposureSpec{t, 0.0, 1}, nullptr));
    }
    auto cpu = [] { return static_cast<double>(std::clock()) / CLOCKS_PER_SEC; };
    for (std::size_t i = 0; i < methods.size(); ++i) {
      const double t0 = cpu();
      int calls = 0;
      for (int rep = 0; rep < 50; ++rep)
        for (const auto& im : imgs) { dets[i].detect(im, 0.0); ++calls; }
      std::printf("detect, %s: %.1f us\n", methods[i].name, 1e6 * (cpu() - t0) / calls);
    }
    std::vector<vision::Circle> circles;
    for (const auto& im : imgs) { auto sc = dets[1].detect(im, 0.0); if (sc.ball_circle) circles.push_back(*sc.ball_circle); else circles.push_back({}); }
    double t0 = cpu(); int calls = 0;
    for (int rep = 0; rep < 50; ++rep)
      for (std::size_t j = 0; j < imgs.size(); ++j) if (circles[j].radius > 0) { vision::refineBallBySphereCone(imgs[j], cam, circles[j], methods[2].cfg.ball_outline_params, 1.0); ++calls; }
    std::printf("refineBallBySphereCone: %.1f us\n", 1e6 * (cpu() - t0) / calls);
    t0 = cpu(); calls = 0;
    for (int rep = 0; rep < 50; ++rep)
      for (std::size_t j = 0; j < imgs.size(); ++j) if (circles[j].radius > 0) { vision::ballOutlinePoints(imgs[j], circles[j], methods[2].cfg.ball_outline_params); ++calls; }
    std::printf("ballOutlinePoints: %.1f us\n", 1e6 * (cpu() - t0) / calls);
  }
  if (n_el) std::printf("same unmixed outline points, %d accepted frames: radius RMS %.4f px with cv::fitEllipse (semi-major axis), %.4f px with the sphere cone\n", n_el, std::sqrt(sq_el / n_el), std::sqrt(sq_cone / n_el));
  std::printf("sphere cone fell back to the greenness ellipse in %d frames\n", fallbacks);
  return 0;
}
