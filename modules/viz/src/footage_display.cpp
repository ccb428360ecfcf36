#include "viewline/viz/footage_display.h"

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

struct FootageDisplay::Impl {
#if defined(VISP_HAVE_X11)
  vpDisplayX display;
#endif
  vpImage<vpRGBa> image;
  bool opened = false;
  DisplayControls controls;
};

FootageDisplay::FootageDisplay() : impl_(std::make_unique<Impl>()) {
#if !defined(VISP_HAVE_X11)
  throw core::InvalidInput("--display: ViSP was built without X11 (vpDisplayX)");
#else
  const char* d = std::getenv("DISPLAY");
  if (d == nullptr || *d == '\0') throw core::InvalidInput("--display: no X display (DISPLAY is not set)");
#endif
}

FootageDisplay::~FootageDisplay() = default;

bool FootageDisplay::show(const runtime::Frame& frame, const scenarios::pan_tilt::FootageStep& step,
                          const std::string& status) {
#if defined(VISP_HAVE_X11)
  if (frame.image.empty()) return !impl_->controls.quitRequested();
  vpImageConvert::convert(frame.image, impl_->image);
  if (!impl_->opened) {
    impl_->display.init(impl_->image, 50, 50, "viewline footage tracker");
    impl_->opened = true;
  }
  auto ip = [](const Eigen::Vector2d& p) { return vpImagePoint(p.y(), p.x()); };
  const vpImage<vpRGBa>& I = impl_->image;
  vpDisplay::display(I);
  const Eigen::Vector2d centre(0.5 * (frame.image.cols - 1), 0.5 * (frame.image.rows - 1));
  vpDisplay::displayCross(I, ip(centre), 21, vpColor::white, 1);
  const cv::Rect& w = step.window;
  if (w.area() > 0)
    vpDisplay::displayRectangle(I, vpImagePoint(w.y, w.x), static_cast<unsigned>(w.width),
                                static_cast<unsigned>(w.height), vpColor::cyan, false, 1);
  if (step.detected) vpDisplay::displayCross(I, ip(step.measured_px), 13, vpColor::red, 2);
  if (step.has_prediction) vpDisplay::displayCircle(I, ip(step.predicted_px), 9, vpColor::green, false, 2);
  char text[160];
  std::snprintf(text, sizeof text, "frame %llu  t=%.3f s  %s", static_cast<unsigned long long>(frame.sequence),
                frame.stamp, step.detected ? "detected" : "LOST");
  vpDisplay::displayText(I, 14, 8, text, vpColor::red);
  vpDisplay::displayText(I, 30, 8, "red detected  green predicted  cyan window  + centre", vpColor::yellow);
  if (!status.empty()) vpDisplay::displayText(I, 46, 8, status, vpColor::orange);
  impl_->controls.drawLegend(I);
  vpDisplay::flush(I);
  return impl_->controls.poll(I);
#else
  (void)frame;
  (void)step;
  (void)status;
  return true;
#endif
}

void FootageDisplay::close() {
  if (impl_->opened) impl_->controls.waitForClose(impl_->image);
}

}  // namespace viewline::viz
