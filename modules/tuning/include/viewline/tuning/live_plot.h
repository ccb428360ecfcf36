#pragma once
// Live curves of a single run (ViSP vpPlot, X11): the error and the NIS as the run goes. Only
// constructed with --display; available() is false headless (no DISPLAY, or ViSP without X11),
// and nothing else in the tuning tool needs a display.

#include <memory>
#include <string>

#include "viewline/tuning/scenario.h"

namespace viewline::tuning {

class LivePlot {
public:
  static bool available();
  /// Throws core::InvalidInput when !available().
  LivePlot(const std::string& title, const std::string& error_label, double nis_dof, double confidence);
  ~LivePlot();
  LivePlot(const LivePlot&) = delete;
  LivePlot& operator=(const LivePlot&) = delete;
  /// Adds a sample (from the running thread; single-run use only).
  void add(const LiveSample& sample);

private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace viewline::tuning
