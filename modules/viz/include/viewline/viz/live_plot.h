#pragma once
// Live curves of a single tuning run (ViSP vpPlot, X11): the error and the NIS as the run goes,
// with a 20-sample moving mean of the NIS and its chi-square band. Only `viewline_tune run
// --display` opens one; available() is false headless (no DISPLAY, or ViSP without X11).
//
//   if (viz::LivePlot::available()) {
//     viz::LivePlot plot("viewline_tune: dart", "error", 2.0, 0.99);
//     plot.add(t, error, nis);   // error NaN / nis < 0 when the sample has none
//   }

#include <memory>
#include <string>

namespace viewline::viz {

/// Live curves of one tuning run (ViSP vpPlot): error and NIS with its moving mean and chi-square band.
class LivePlot {
public:
  /// True when a plot can open (ViSP built with X11 and a DISPLAY set); false headless.
  static bool available();
  /// Throws core::InvalidInput when !available().
  LivePlot(const std::string& title, const std::string& error_label, double nis_dof, double confidence);
  ~LivePlot();
  LivePlot(const LivePlot&) = delete;
  LivePlot& operator=(const LivePlot&) = delete;
  /// Adds a sample at abscissa t: an error (NaN: none) and a NIS (< 0: none). From one thread.
  void add(double t, double error, double nis);

private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace viewline::viz
