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

PlannerInput::PlannerInput(const BallCatchingConfig& cfg, std::vector<core::Camera> cameras)
    : enabled_(cfg.flight_fit.enabled),
      bias_sigma_px_(cfg.tracker.pixel_bias.sigma_px),
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
  const double sigma = bias_sigma_px_ > 0.0 ? std::hypot(m.sigma_px, bias_sigma_px_) : m.sigma_px;
  const std::optional<estimation::StateEstimate> fitted = fit_.add({m.camera, m.t, m.uv, sigma}, tracker.state());
  return fitted ? *fitted : tracker.state();
}

void PlannerInput::reset() {
  fit_.reset();
  track_ = restarts_ = -1;
}

}  // namespace viewline::scenarios
