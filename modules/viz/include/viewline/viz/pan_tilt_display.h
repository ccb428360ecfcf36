#pragma once
// Live view of the pan-tilt scenario (ViSP vpDisplayX): the camera image with the image centre
// (white cross), the measured target (detection + [T] noise, red cross), the predicted target at
// the command's effect time (green circle), the true target (blue point), the error vector from
// the centre to the true target (yellow line), and the controller, mode, time and error in pixels.
// Footage and cameras have no truth: then only the centre, the measurement and the prediction; on a
// live source also the frames missed so far and the last frame's processing time.
// A frame sink of the loop (pan_tilt::FrameSink): the scheduler paces the run, the keys of
// viz::DisplayControls pause, step and quit it, and close() keeps the window open at the end.

#include <memory>

#include "viewline/scenarios/pan_tilt/telemetry.h"

namespace viewline::viz {

/// Live view of the pan-tilt scenario: camera image with centre, measured, predicted and true target and the
/// error vector.
class PanTiltDisplay : public scenarios::pan_tilt::FrameSink {
public:
  /// Throws core::InvalidInput when ViSP has no X11 support or no X display is available.
  PanTiltDisplay();
  ~PanTiltDisplay() override;
  PanTiltDisplay(const PanTiltDisplay&) = delete;
  PanTiltDisplay& operator=(const PanTiltDisplay&) = delete;

  /// Draws one frame of the loop and polls the keys (blocks while paused).
  void frame(const scenarios::pan_tilt::FrameRecord& r) override;
  /// True once the viewer pressed q: the loop ends the run.
  bool quitRequested() const override;
  /// After the run: waits for a click or a key (at once when the viewer quit).
  void close();

private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace viewline::viz
