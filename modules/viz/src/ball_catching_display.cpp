#include "viewline/viz/ball_catching_display.h"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <cstdio>
#include <vector>
#include <visp3/core/vpConfig.h>
#include <visp3/core/vpImage.h>
#include <visp3/core/vpImageConvert.h>
#include <visp3/gui/vpDisplayX.h>

#include "viewline/core/error.h"
#include "viewline/viz/display_controls.h"

namespace viewline::viz {

#if defined(VISP_HAVE_X11)
struct BallCatchingDisplay::Impl {
  std::vector<std::unique_ptr<vpImage<vpRGBa>>> images;
  std::vector<std::unique_ptr<vpDisplayX>> displays;
  DisplayControls controls;
  explicit Impl(const scenarios::BallCatchingConfig& cfg) {
    int x = 0;
    for (std::size_t i = 0; i < cfg.activeCameras(); ++i) {
      const auto& c = cfg.cameras[i];
      images.push_back(std::make_unique<vpImage<vpRGBa>>(c.height, c.width));
      displays.push_back(std::make_unique<vpDisplayX>());
      displays.back()->init(*images.back(), x, 0, "ball_catching: " + c.name);
      x += static_cast<int>(c.width) + 10;
    }
  }
};
#else
struct BallCatchingDisplay::Impl {};
#endif

BallCatchingDisplay::BallCatchingDisplay(const scenarios::BallCatchingConfig& cfg) {
#if defined(VISP_HAVE_X11)
  impl_ = std::make_unique<Impl>(cfg);
#else
  (void)cfg;
  throw core::InvalidInput("--display: ViSP was built without X11 (vpDisplayX)");
#endif
}

BallCatchingDisplay::~BallCatchingDisplay() = default;

bool BallCatchingDisplay::show(const scenarios::CatchFrame& f) {
#if defined(VISP_HAVE_X11)
  if (f.camera >= impl_->images.size() || !f.image || !f.camera_model) return !impl_->controls.quitRequested();
  vpImage<vpRGBa>& I = *impl_->images[f.camera];
  vpImageConvert::convert(*f.image, I);
  vpDisplay::display(I);
  const core::Camera& cam = *f.camera_model;
  auto ip = [](const Eigen::Vector2d& uv) { return vpImagePoint(uv.y(), uv.x()); };
  if (f.detection) vpDisplay::displayCross(I, ip(*f.detection), 14, vpColor::green, 2);
  if (f.estimate)
    if (auto uv = cam.project(*f.estimate)) vpDisplay::displayCircle(I, ip(*uv), 5, vpColor::blue, false, 2);
  if (auto uv = cam.project(f.hole)) vpDisplay::displayCircle(I, ip(*uv), 6, vpColor::white, false, 2);
  if (f.crossing) {
    if (auto uv = cam.project(f.crossing->p)) vpDisplay::displayCross(I, ip(*uv), 16, vpColor::yellow, 2);
    // 2σ ellipse of the crossing point (in the plane), drawn as projected points.
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(f.crossing->cov_p);
    const Eigen::Vector3d a = 2.0 * std::sqrt(std::max(0.0, es.eigenvalues()(2))) * es.eigenvectors().col(2);
    const Eigen::Vector3d b = 2.0 * std::sqrt(std::max(0.0, es.eigenvalues()(1))) * es.eigenvectors().col(1);
    for (int k = 0; k < 36; ++k) {
      const double th = k * 2.0 * M_PI / 36.0;
      if (auto uv = cam.project(f.crossing->p + std::cos(th) * a + std::sin(th) * b))
        vpDisplay::displayPoint(I, ip(*uv), vpColor::yellow, 2);
    }
  }
  char text[160];
  std::snprintf(text, sizeof text, "throw %d  t = %.3f s%s", f.throw_index, f.t, f.crossing ? "  target set" : "");
  vpDisplay::displayText(I, 14, 6, text, vpColor::yellow);
  impl_->controls.drawLegend(I);
  vpDisplay::flush(I);
  return impl_->controls.poll(I);
#else
  (void)f;
  return true;
#endif
}

void BallCatchingDisplay::waitForClose() {
#if defined(VISP_HAVE_X11)
  if (!impl_->images.empty()) impl_->controls.waitForClose(*impl_->images.front());
#endif
}

}  // namespace viewline::viz
