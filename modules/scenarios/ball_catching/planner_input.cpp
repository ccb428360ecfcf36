#include "viewline/scenarios/ball_catching/planner_input.h"

#include <cmath>

namespace viewline::scenarios {

estimation::DragBallisticModel flightFitModel(const BallCatchingConfig& cfg) {
  const planning::CrossingModel m = cfg.plannerConfig().model;
  estimation::DragBallisticModel d;
  d.g = m.gravity_w.norm();
  d.up = -m.gravity_w / d.g;
  d.k = m.kind == planning::FlightModel::Drag ? m.drag_k : 0.0;
  d.q = 0.0;
  return d;
}

namespace {
std::vector<double> biasSigmas(const BallCatchingConfig& cfg) {
  const tracking::TrackerConfig t = cfg.trackerConfig();
  std::vector<double> s(cfg.activeCameras(), 0.0);
  if (t.pixel_bias.enabled())
    for (std::size_t c = 0; c < s.size(); ++c) s[c] = t.pixel_bias.sigmaOf(c);
  return s;
}
}  // namespace

PlannerInput::PlannerInput(const BallCatchingConfig& cfg, std::vector<core::Camera> cameras)
    : enabled_(cfg.flight_fit.enabled),
      bias_sigma_px_(biasSigmas(cfg)),
      fit_(cfg.flight_fit, std::move(cameras), flightFitModel(cfg), FitAimPlane{cfg.robot.home, cfg.box_normal}) {}

estimation::StateEstimate PlannerInput::after(const tracking::ImageMeasurement& m,
                                              const tracking::ViewlineTracker& tracker) {
  if (!enabled_) return tracker.state();
  const tracking::TrackState& ts = tracker.trackState();
  if (ts.tracks_started != track_ || ts.restarts != restarts_) {  // a new track: a new fit
    fit_.reset();
    track_ = ts.tracks_started;
    restarts_ = ts.restarts;
  }
  // The fit weighs its images as white; with the tracker's pixel bias on, m.sigma_px is only the
  // white part, and the fit is given the total (white and bias in quadrature) as before.
  const double bias = m.camera < bias_sigma_px_.size() ? bias_sigma_px_[m.camera] : 0.0;
  const double sigma = bias > 0.0 ? std::hypot(m.sigma_px, bias) : m.sigma_px;
  const std::optional<estimation::StateEstimate> fitted = fit_.add({m.camera, m.t, m.uv, sigma}, tracker.state());
  return fitted ? *fitted : tracker.state();
}

void PlannerInput::reset() {
  fit_.reset();
  track_ = restarts_ = -1;
}

}  // namespace viewline::scenarios
