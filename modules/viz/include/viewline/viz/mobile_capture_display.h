#pragma once
// Live view of the mobile-capture scenario (ViSP vpDisplayX): the head camera image (detection
// marked) and a top view of the floor around the robot: robot (body, heading, gripper), true
// object (red), estimate (blue), predicted path (green), capture point (yellow cross). The top
// view takes the keys of viz::DisplayControls (space pause, n step, q quit); the run is paced by
// its scheduler (MobileCaptureHooks::pacing), so a person sees it at the speed it happens.
//
//   viz::MobileCaptureDisplay view(cfg);
//   hooks.on_frame = [&](const scenarios::MobileCaptureFrame& f) { view.show(f); };
//   hooks.quit_requested = [&] { return view.quitRequested(); };
//   hooks.pacing = runtime::Pacing{1.0};
//   ... runMobileCapture(cfg, seed, &hooks);
//   view.waitForClose();

#include <memory>

#include "viewline/scenarios/mobile_capture.h"

namespace viewline::viz {

/// Live view of the mobile-capture scenario: head camera image and a top view of robot, object, estimate,
/// path and capture point.
class MobileCaptureDisplay {
public:
  /// `top_size` pixels for `top_span` metres of floor. Throws core::InvalidInput without X11.
  explicit MobileCaptureDisplay(const scenarios::MobileCaptureConfig& cfg, int top_size = 480, double top_span = 6.0);
  ~MobileCaptureDisplay();
  /// Draws one frame and polls the keys (blocks while paused).
  void show(const scenarios::MobileCaptureFrame& frame);
  /// The quit key was pressed: the run should end.
  bool quitRequested() const;
  /// After the run: waits for a click or a key (at once when quit was asked).
  void waitForClose();

private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace viewline::viz
