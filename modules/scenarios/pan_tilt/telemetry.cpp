#include "viewline/scenarios/pan_tilt/telemetry.h"

#include <cmath>

#include "viewline/io/log.h"

namespace viewline::scenarios::pan_tilt {

const std::vector<std::string>& FrameCsvSink::columns() {
  static const std::vector<std::string> c{"t",      "truth_x", "truth_y", "detected", "meas_x",  "meas_y",
                                          "filt_x", "filt_y",  "truth_u", "truth_v",  "meas_u",  "meas_v",
                                          "pred_u", "pred_v",  "error_px", "pan",     "tilt",    "pan_rate",
                                          "tilt_rate", "cmd_pan", "cmd_tilt", "mode"};
  return c;
}

void FrameCsvSink::runStarted(const std::string& controller) {
  csv_ = log_.enabled() ? &log_.stream(controller + "_frames", columns(), 17) : nullptr;
}

void FrameCsvSink::frame(const FrameRecord& r) {
  if (csv_ == nullptr) return;
  const double nan = std::nan("");
  csv_->row({r.t, r.truth.x(), r.truth.y(), r.detected ? 1.0 : 0.0, r.detected ? r.measured.x() : nan,
             r.detected ? r.measured.y() : nan, r.filtered.x(), r.filtered.y(), r.truth_px.x(), r.truth_px.y(),
             r.measured_px.x(), r.measured_px.y(), r.predicted_px.x(), r.predicted_px.y(), r.error_px, r.q(0), r.q(1),
             r.qdot(0), r.qdot(1), r.command(0), r.command(1), static_cast<double>(r.mode)});
}

void FrameFanout::runStarted(const std::string& controller) {
  for (FrameSink* s : sinks_) s->runStarted(controller);
}

void FrameFanout::frame(const FrameRecord& r) {
  for (FrameSink* s : sinks_) s->frame(r);
}

bool FrameFanout::quitRequested() const {
  for (const FrameSink* s : sinks_)
    if (s->quitRequested()) return true;
  return false;
}

}  // namespace viewline::scenarios::pan_tilt
