#include "viewline/viz/live_plot.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <visp3/core/vpConfig.h>
#include <visp3/gui/vpPlot.h>

#include "viewline/core/error.h"
#include "viewline/core/statistics.h"

namespace viewline::viz {

struct LivePlot::Impl {
#if defined(VISP_HAVE_X11) || defined(VISP_HAVE_OPENCV)
  std::unique_ptr<vpPlot> plot;
#endif
  double lo = 0.0, hi = 0.0, dof = 2.0;
  double ma = 0.0;
  std::size_t n = 0;
};

bool LivePlot::available() {
#if defined(VISP_HAVE_X11)
  const char* d = std::getenv("DISPLAY");
  return d != nullptr && *d != '\0';
#else
  return false;
#endif
}

LivePlot::LivePlot(const std::string& title, const std::string& error_label, double nis_dof, double confidence)
    : impl_(std::make_unique<Impl>()) {
  if (!available()) throw core::InvalidInput("--display: no X display (DISPLAY unset) or ViSP built without X11");
#if defined(VISP_HAVE_X11)
  // Band of a 20-sample moving mean of the NIS.
  const core::Interval b = core::averagedChiSquareInterval(nis_dof, 20.0, confidence);
  impl_->lo = b.lo;
  impl_->hi = b.hi;
  impl_->dof = nis_dof;
  impl_->plot = std::make_unique<vpPlot>(2, 700, 700, 700, 10, title.c_str());
  impl_->plot->initGraph(0, 1);
  impl_->plot->setTitle(0, error_label.c_str());
  impl_->plot->setLegend(0, 0, "error");
  impl_->plot->initGraph(1, 4);
  impl_->plot->setTitle(1, "NIS: samples, 20-sample mean, band");
  impl_->plot->setLegend(1, 0, "NIS");
  impl_->plot->setLegend(1, 1, "mean(20)");
  impl_->plot->setLegend(1, 2, "band lo");
  impl_->plot->setLegend(1, 3, "band hi");
  impl_->plot->setColor(1, 0, vpColor::lightBlue);
  impl_->plot->setColor(1, 1, vpColor::blue);
  impl_->plot->setColor(1, 2, vpColor::red);
  impl_->plot->setColor(1, 3, vpColor::red);
#else
  (void)title;
  (void)error_label;
  (void)nis_dof;
  (void)confidence;
#endif
}

LivePlot::~LivePlot() = default;

void LivePlot::add(double t, double error, double nis) {
#if defined(VISP_HAVE_X11)
  if (!impl_->plot) return;
  if (std::isfinite(error)) impl_->plot->plot(0, 0, t, error);
  if (nis >= 0.0) {
    ++impl_->n;
    const double w = static_cast<double>(std::min<std::size_t>(impl_->n, 20));
    impl_->ma += (nis - impl_->ma) / w;
    impl_->plot->plot(1, 0, t, nis);
    impl_->plot->plot(1, 1, t, impl_->ma);
    impl_->plot->plot(1, 2, t, impl_->lo);
    impl_->plot->plot(1, 3, t, impl_->hi);
  }
#else
  (void)t;
  (void)error;
  (void)nis;
#endif
}

}  // namespace viewline::viz
