#pragma once
// What the catch planner predicts from after each fused image, one rule for the in-process loop
// (loop.cpp) and the DDS tracker node (modules/nodes): the drag-model flight fit of the current
// track's images (flight_fit.h, with the throw prior and the aim plane through the robot's home)
// once it answers, the tracker's own estimate before, or always when flight_fit.enabled is false.
// A new track or a restart of the tracker starts a new fit.

#include <vector>

#include "viewline/core/camera.h"
#include "viewline/estimation/models/ballistic_drag.h"
#include "viewline/estimation/state.h"
#include "viewline/scenarios/ball_catching/config.h"
#include "viewline/scenarios/ball_catching/flight_fit.h"
#include "viewline/tracking/tracker.h"

namespace viewline::scenarios {

/// Gravity and drag of the flight as cfg's planner models it (one owner: cfg.plannerConfig()),
/// with q = 0: the flight fit's model.
estimation::DragBallisticModel flightFitModel(const BallCatchingConfig& cfg);

/// The planner's input after each fused image (header comment).
class PlannerInput {
public:
  /// The fit of cfg's flight over `cameras` (the estimator's cameras, registered to the robot).
  PlannerInput(const BallCatchingConfig& cfg, std::vector<core::Camera> cameras);
  /// The state the planner predicts from after `tracker` fused image m (call after the update).
  estimation::StateEstimate after(const tracking::ImageMeasurement& m, const tracking::ViewlineTracker& tracker);
  /// Forgets the track (the next image starts a new fit).
  void reset();

private:
  bool enabled_;
  std::vector<double> bias_sigma_px_;  // per camera: the tracker's pixel-bias std (0: none), added to the fit's σ in quadrature
  FlightFit fit_;
  int track_ = -1, restarts_ = -1;  // the tracker's track the fit belongs to
};

}  // namespace viewline::scenarios
