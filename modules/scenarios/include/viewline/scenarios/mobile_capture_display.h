#pragma once
// Live view of the mobile-capture scenario (ViSP vpDisplayX): the head camera image (detection
// marked) and a top view of the floor around the robot: robot (body, heading, gripper), true
// object (red), estimate (blue), predicted path (green), capture point (yellow cross). Only
// constructed with --display; needs an X display.

#include <memory>

#include "viewline/scenarios/mobile_capture.h"

namespace viewline::scenarios {

class MobileCaptureDisplay {
public:
  /// `top_size` pixels for `top_span` metres of floor.
  explicit MobileCaptureDisplay(const MobileCaptureConfig& cfg, int top_size = 480, double top_span = 6.0);
  ~MobileCaptureDisplay();
  void show(const MobileCaptureFrame& frame);

private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace viewline::scenarios
