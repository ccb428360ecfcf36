#include "viewline/viz/mobile_capture_display.h"

#include <cmath>
#include <visp3/core/vpConfig.h>
#include <visp3/core/vpImage.h>
#include <visp3/core/vpImageConvert.h>
#include <visp3/gui/vpDisplayX.h>

#include "viewline/core/error.h"
#include "viewline/viz/display_controls.h"

namespace viewline::viz {

using scenarios::MobileCaptureConfig;
using scenarios::MobileCaptureFrame;

#if defined(VISP_HAVE_X11)
struct MobileCaptureDisplay::Impl {
  MobileCaptureConfig cfg;
  int size;
  double span;
  vpImage<vpRGBa> camera, top;
  vpDisplayX d_camera, d_top;
  DisplayControls controls;
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  Impl(const MobileCaptureConfig& c, int s, double sp)
      : cfg(c), size(s), span(sp), camera(c.height, c.width), top(static_cast<unsigned>(s), static_cast<unsigned>(s)) {
    d_camera.init(camera, 0, 0, "mobile_capture: head camera");
    d_top.init(top, static_cast<int>(c.width) + 20, 0, "mobile_capture: top view");
  }
  vpImagePoint toTop(const Eigen::Vector2d& p) const {
    const double scale = size / span;
    return vpImagePoint(size / 2.0 - (p.y() - centre.y()) * scale, size / 2.0 + (p.x() - centre.x()) * scale);
  }
};
#else
struct MobileCaptureDisplay::Impl {};
#endif

MobileCaptureDisplay::MobileCaptureDisplay(const MobileCaptureConfig& cfg, int top_size, double top_span) {
#if defined(VISP_HAVE_X11)
  impl_ = std::make_unique<Impl>(cfg, top_size, top_span);
#else
  (void)cfg, (void)top_size, (void)top_span;
  throw core::InvalidInput("--display: ViSP was built without X11 (vpDisplayX)");
#endif
}

MobileCaptureDisplay::~MobileCaptureDisplay() = default;

void MobileCaptureDisplay::show(const MobileCaptureFrame& f) {
#if defined(VISP_HAVE_X11)
  Impl& m = *impl_;
  if (f.image && !f.image->empty()) vpImageConvert::convert(*f.image, m.camera);
  vpDisplay::display(m.camera);
  if (f.detected) vpDisplay::displayCross(m.camera, vpImagePoint(f.pixel.y(), f.pixel.x()), 12, vpColor::green, 2);
  char text[128];
  std::snprintf(text, sizeof text, "t = %.1f s  tilt %.0f  pan %.0f deg", f.t, f.joints.tilt * 57.2958,
                f.joints.pan * 57.2958);
  vpDisplay::displayText(m.camera, 12, 5, text, vpColor::yellow);
  vpDisplay::flush(m.camera);

  // Top view centred between robot and object, floor as a grid every metre.
  m.centre = 0.5 * (Eigen::Vector2d(f.robot.x, f.robot.y) + f.object_true);
  m.top = vpRGBa(40, 40, 40);
  vpDisplay::display(m.top);
  const double half = 0.5 * m.span;
  for (double g = std::floor(m.centre.x() - half); g <= m.centre.x() + half; g += 1.0)
    vpDisplay::displayLine(m.top, m.toTop({g, m.centre.y() - half}), m.toTop({g, m.centre.y() + half}), vpColor(80, 80, 80));
  for (double g = std::floor(m.centre.y() - half); g <= m.centre.y() + half; g += 1.0)
    vpDisplay::displayLine(m.top, m.toTop({m.centre.x() - half, g}), m.toTop({m.centre.x() + half, g}), vpColor(80, 80, 80));
  const double scale = m.size / m.span;
  const Eigen::Vector2d r(f.robot.x, f.robot.y), h(std::cos(f.robot.theta), std::sin(f.robot.theta));
  vpDisplay::displayCircle(m.top, m.toTop(r), 0.2 * scale, vpColor::white, false, 2);
  vpDisplay::displayArrow(m.top, m.toTop(r), m.toTop(r + 0.3 * h), vpColor::white, 6, 4, 2);
  const Eigen::Vector2d grip = r + 0.5 * (m.cfg.jaws.x_min + m.cfg.jaws.x_max) * h;
  vpDisplay::displayCircle(m.top, m.toTop(grip), m.cfg.jaws.half_width * scale, vpColor::orange, false, 1);
  for (std::size_t i = 0; i < f.prediction.size(); i += 2) vpDisplay::displayPoint(m.top, m.toTop(f.prediction[i]), vpColor::green, 2);
  if (f.estimate_valid) {
    vpDisplay::displayCircle(m.top, m.toTop(f.estimate.head<2>()), 5, vpColor::blue, true);
    vpDisplay::displayCross(m.top, m.toTop(f.plan.point), 14, vpColor::yellow, 2);
  }
  vpDisplay::displayCircle(m.top, m.toTop(f.object_true), 4, vpColor::red, true);
  std::snprintf(text, sizeof text, "t = %.1f s  %s  capture in %.1f s%s", f.t,
                f.mode == control::SearchMode::Tracking ? "tracking"
                : f.mode == control::SearchMode::Lost   ? "lost"
                                                        : "searching",
                f.plan.time, f.plan.reachable ? "" : " (not reachable)");
  vpDisplay::displayText(m.top, 12, 5, text, vpColor::yellow);
  m.controls.drawLegend(m.top);
  vpDisplay::flush(m.top);
  m.controls.poll(m.top);
#else
  (void)f;
#endif
}

bool MobileCaptureDisplay::quitRequested() const {
#if defined(VISP_HAVE_X11)
  return impl_->controls.quitRequested();
#else
  return true;
#endif
}

void MobileCaptureDisplay::waitForClose() {
#if defined(VISP_HAVE_X11)
  impl_->controls.waitForClose(impl_->top);
#endif
}

}  // namespace viewline::viz
