#pragma once
// Live view of the pan-tilt scenario (ViSP vpDisplayX; only constructed with --display and an X
// display): the camera image with the image centre (white cross), the measured target (detection
// + [T] noise, red cross), the predicted target at the command's effect time (green circle), the
// true target (blue point), the error vector from the centre to the true target (yellow line),
// and the controller, mode, time and error in pixels.

#include <memory>

#include "viewline/scenarios/pan_tilt_scenario.h"

namespace viewline::scenarios {

class PanTiltDisplay {
public:
  /// Throws core::InvalidInput when ViSP has no X11 support or no X display is available.
  PanTiltDisplay();
  ~PanTiltDisplay();
  PanTiltDisplay(const PanTiltDisplay&) = delete;
  PanTiltDisplay& operator=(const PanTiltDisplay&) = delete;
  void show(const PanTiltFrameView& view);

private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace viewline::scenarios
