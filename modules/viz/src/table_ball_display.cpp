#include "viewline/viz/table_ball_display.h"

#include <cmath>
#include <visp3/core/vpConfig.h>
#include <visp3/core/vpImage.h>
#include <visp3/core/vpImageConvert.h>
#include <visp3/core/vpRGBa.h>
#include <visp3/gui/vpDisplayX.h>

#include "viewline/core/error.h"
#include "viewline/core/frames.h"
#include "viewline/viz/display_controls.h"

namespace viewline::viz {

struct TableBallDisplay::Impl {
  double side, radius;
  int top_px;
  std::size_t track_length;
  vpImage<vpRGBa> camera_image, top_image;
#if defined(VISP_HAVE_X11)
  vpDisplayX camera_display, top_display;
#endif
  bool initialised = false;
  DisplayControls controls;
  std::deque<Eigen::Vector2d> measured, filtered, truth;

  vpImagePoint topPixel(const Eigen::Vector2d& p) const {
    // Table x to the right, y up in the top view; the border ring fits in the window.
    const double scale = 0.9 * top_px / (side + 0.04);
    return vpImagePoint(0.5 * top_px - scale * p.y(), 0.5 * top_px + scale * p.x());
  }
  static void push(std::deque<Eigen::Vector2d>& d, const Eigen::Vector2d& p, std::size_t n) {
    d.push_back(p);
    while (d.size() > n) d.pop_front();
  }
};

TableBallDisplay::TableBallDisplay(double table_side, double ball_radius, int top_view_px, std::size_t track_length)
    : impl_(std::make_unique<Impl>()) {
#if !defined(VISP_HAVE_X11)
  throw core::InvalidInput("--display: ViSP was built without X11 (vpDisplayX)");
#endif
  impl_->side = table_side;
  impl_->radius = ball_radius;
  impl_->top_px = top_view_px;
  impl_->track_length = track_length;
  impl_->top_image.resize(static_cast<unsigned>(top_view_px), static_cast<unsigned>(top_view_px), vpRGBa(255, 255, 255));
}

TableBallDisplay::~TableBallDisplay() = default;

bool TableBallDisplay::show(const scenarios::TableBallFrameView& view) {
#if defined(VISP_HAVE_X11)
  Impl& d = *impl_;
  const scenarios::ObserverFrame& of = *view.observer;
  if (view.image != nullptr) vpImageConvert::convert(*view.image, d.camera_image);
  if (!d.initialised) {
    if (view.image == nullptr) return true;
    d.camera_display.init(d.camera_image, 50, 50, "table_ball_balancing: head camera");
    d.top_display.init(d.top_image, 80 + static_cast<int>(d.camera_image.getWidth()), 50, "top view: measured (red), filtered (green), truth (blue)");
    d.initialised = true;
  }
  // --- camera view ([M] Fig. 12) ---
  vpDisplay::display(d.camera_image);
  const core::Camera& cam = *view.camera;
  if (of.table_found) {
    for (const auto& c : of.corners) vpDisplay::displayCross(d.camera_image, vpImagePoint(c.y(), c.x()), 9, vpColor::yellow, 2);
    vpDisplay::displayFrame(d.camera_image, core::toVisp(of.c_M_t), cam.intrinsics, 0.08, vpColor::none, 2);
  }
  if (of.ball_circle) {
    vpDisplay::displayCircle(d.camera_image, vpImagePoint(of.ball_circle->center.y(), of.ball_circle->center.x()),
                             of.ball_circle->radius, vpColor::cyan, false, 1);
  }
  auto project = [&](const Eigen::Vector2d& p) {
    const Eigen::Vector3d pc = of.c_M_t * Eigen::Vector3d(p.x(), p.y(), d.radius);
    const Eigen::Vector2d uv = cam.normalizedToPixel(pc.head<2>() / pc.z());
    return vpImagePoint(uv.y(), uv.x());
  };
  if (of.estimate_valid) {
    vpDisplay::displayCross(d.camera_image, project({of.x[0], of.x[2]}), 11, vpColor::green, 2);
    for (const auto& p : of.predictions) vpDisplay::displayPoint(d.camera_image, project(p), vpColor::orange, 3);
  }
  vpDisplay::displayText(d.camera_image, 12, 8, of.ball_found ? "ball found" : ("no ball: " + of.failure).c_str(),
                         vpColor::white);
  d.controls.drawLegend(d.camera_image);
  vpDisplay::flush(d.camera_image);

  // --- top view ---
  if (of.ball_found) Impl::push(d.measured, of.measured, d.track_length);
  if (of.estimate_valid) Impl::push(d.filtered, Eigen::Vector2d(of.x[0], of.x[2]), d.track_length);
  // On footage there is no truth (NaN): nothing of it is drawn.
  const bool has_truth = view.truth.allFinite();
  if (has_truth) Impl::push(d.truth, view.truth, d.track_length);
  vpDisplay::display(d.top_image);
  const double h = 0.5 * d.side;
  const vpImagePoint tl = d.topPixel({-h, h}), br = d.topPixel({h, -h});
  vpDisplay::displayRectangle(d.top_image, tl, br, vpColor(200, 30, 30), true);
  vpDisplay::displayRectangle(d.top_image, d.topPixel({-h - 0.02, h + 0.02}), d.topPixel({h + 0.02, -h - 0.02}),
                              vpColor::black, false, 3);
  for (const auto& p : d.measured) vpDisplay::displayPoint(d.top_image, d.topPixel(p), vpColor(255, 230, 230), 3);
  for (const auto& p : d.truth) vpDisplay::displayPoint(d.top_image, d.topPixel(p), vpColor::blue, 2);
  for (std::size_t i = 1; i < d.filtered.size(); ++i) {
    vpDisplay::displayLine(d.top_image, d.topPixel(d.filtered[i - 1]), d.topPixel(d.filtered[i]), vpColor::green, 2);
  }
  vpDisplay::displayCross(d.top_image, d.topPixel(view.setpoint), 15, vpColor::white, 2);
  const double scale = 0.9 * d.top_px / (d.side + 0.04);
  if (has_truth) vpDisplay::displayCircle(d.top_image, d.topPixel(view.truth), scale * d.radius, vpColor::blue, false, 1);
  char text[128];
  std::snprintf(text, sizeof text, "t = %.2f s  tilt (%.1f, %.1f) deg", of.t, core::rad2deg(view.tilt.x()),
                core::rad2deg(view.tilt.y()));
  vpDisplay::displayText(d.top_image, 14, 8, text, vpColor::black);
  vpDisplay::flush(d.top_image);
  return d.controls.poll(d.camera_image);
#else
  (void)view;
  return true;
#endif
}

void TableBallDisplay::waitForClose() {
  if (impl_->initialised) impl_->controls.waitForClose(impl_->camera_image);
}

}  // namespace viewline::viz
