#include "viewline/viz/pan_tilt_display.h"

#include <cstdio>
#include <cstdlib>
#include <visp3/core/vpConfig.h>
#include <visp3/core/vpImage.h>
#include <visp3/core/vpImageConvert.h>
#include <visp3/core/vpRGBa.h>
#include <visp3/gui/vpDisplayX.h>

#include "viewline/core/error.h"
#include "viewline/viz/display_controls.h"

namespace viewline::viz {

struct PanTiltDisplay::Impl {
#if defined(VISP_HAVE_X11)
  vpDisplayX display;
#endif
  vpImage<vpRGBa> image;
  bool opened = false;
  DisplayControls controls;
};

PanTiltDisplay::PanTiltDisplay() : impl_(std::make_unique<Impl>()) {
#if !defined(VISP_HAVE_X11)
  throw core::InvalidInput("--display: ViSP was built without X11 (vpDisplayX)");
#else
  const char* d = std::getenv("DISPLAY");
  if (d == nullptr || *d == '\0') throw core::InvalidInput("--display: no X display (DISPLAY is not set); use --headless");
#endif
}

PanTiltDisplay::~PanTiltDisplay() = default;

bool PanTiltDisplay::quitRequested() const { return impl_->controls.quitRequested(); }

void PanTiltDisplay::frame(const scenarios::pan_tilt::FrameRecord& v) {
#if defined(VISP_HAVE_X11)
  if (v.image == nullptr) return;
  vpImageConvert::convert(*v.image, impl_->image);
  if (!impl_->opened) {
    impl_->display.init(impl_->image, 50, 50, "viewline pan-tilt tracking");
    impl_->opened = true;
  }
  auto ip = [](const Eigen::Vector2d& p) { return vpImagePoint(p.y(), p.x()); };
  const vpImage<vpRGBa>& I = impl_->image;
  vpDisplay::display(I);
  vpDisplay::displayCross(I, ip(v.principal_px), 21, vpColor::white, 1);
  const bool truth = v.truth_px.allFinite();  // footage and cameras have none
  if (truth) {
    vpDisplay::displayLine(I, ip(v.principal_px), ip(v.truth_px), vpColor::yellow, 1);
    vpDisplay::displayPoint(I, ip(v.truth_px), vpColor::blue, 4);
  }
  if (v.detected) vpDisplay::displayCross(I, ip(v.measured_px), 13, vpColor::red, 2);
  if (v.has_prediction) vpDisplay::displayCircle(I, ip(v.predicted_px), 9, vpColor::green, false, 2);
  char text[160];
  if (truth)
    std::snprintf(text, sizeof text, "%s  t=%.2f s  %s  error %.1f px", v.controller.c_str(), v.t, v.mode_name.c_str(),
                  v.error_px);
  else
    std::snprintf(text, sizeof text, "%s  t=%.2f s  %s", v.controller.c_str(), v.t, v.mode_name.c_str());
  vpDisplay::displayText(I, 14, 8, text, vpColor::red);
  vpDisplay::displayText(I, 30, 8,
                         truth ? "red: measured  green: predicted  blue: true  yellow: error  white: image centre"
                               : "red: measured  green: predicted  white: image centre",
                         vpColor::yellow);
  if (!v.live_status.empty()) vpDisplay::displayText(I, 46, 8, v.live_status, vpColor::orange);
  impl_->controls.drawLegend(I);
  vpDisplay::flush(I);
  impl_->controls.poll(I);
#else
  (void)v;
#endif
}

void PanTiltDisplay::close() {
  if (impl_->opened) impl_->controls.waitForClose(impl_->image);
}

}  // namespace viewline::viz
