#pragma once
// Live view of the ball-catching scenario (ViSP vpDisplayX): one window per camera with the image,
// the detection (green cross), the tracker's position estimate (blue), the planner's predicted
// crossing point (yellow cross, with its 2σ ellipse projected from the plane) and the hole's
// current position (white circle); the keys of viz::DisplayControls (space pause, n step, q quit).
// A consumer of scenarios::CatchHooks::on_frame: the app wires show() there.

#include <memory>

#include "viewline/scenarios/ball_catching/config.h"
#include "viewline/scenarios/ball_catching/loop.h"

namespace viewline::viz {

/// Live view of the ball-catching scenario: per camera the image, detection, estimate, predicted crossing (2σ
/// ellipse) and the hole.
class BallCatchingDisplay {
public:
  /// Opens the windows; throws core::InvalidInput when ViSP has no X11 display.
  explicit BallCatchingDisplay(const scenarios::BallCatchingConfig& cfg);
  ~BallCatchingDisplay();
  /// Draws one image; false once the viewer pressed q (the run should stop).
  bool show(const scenarios::CatchFrame& frame);
  /// After the run: keeps the windows open until a click or a key (at once after q).
  void waitForClose();

private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace viewline::viz
