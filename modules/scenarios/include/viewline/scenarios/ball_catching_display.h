#pragma once
// Live view of the ball-catching scenario (ViSP vpDisplayX): one window per camera with the image,
// the detection (green cross), the tracker's position estimate (blue), the planner's predicted
// crossing point (yellow cross, with its 2σ ellipse projected from the plane) and the hole's
// current position (white circle). Only constructed with --display; needs an X display.

#include <memory>

#include "viewline/scenarios/ball_catching.h"

namespace viewline::scenarios {

class BallCatchingDisplay {
public:
  explicit BallCatchingDisplay(const BallCatchingConfig& cfg);
  ~BallCatchingDisplay();
  void show(const CatchFrame& frame);

private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace viewline::scenarios
