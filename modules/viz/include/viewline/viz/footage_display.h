#pragma once
// Live view of the footage tracker (scenarios::pan_tilt::trackFootage; ViSP vpDisplayX): the camera
// image with the image centre (white cross), the search window (cyan), the detection (red cross),
// the filter's prediction at the frame's stamp (green circle), the frame's stamp and, on a live
// source, the frames missed so far and the last frame's processing time. The keys of
// viz::DisplayControls pause, step and quit; close() keeps the window open at the end.

#include <memory>
#include <string>

#include "viewline/runtime/frame_source.h"
#include "viewline/scenarios/pan_tilt/footage.h"

namespace viewline::viz {

/// Live view of the footage tracker: camera image with centre, search window, detection and prediction.
class FootageDisplay {
public:
  /// Throws core::InvalidInput when ViSP has no X11 support or no X display is available.
  FootageDisplay();
  ~FootageDisplay();
  FootageDisplay(const FootageDisplay&) = delete;
  FootageDisplay& operator=(const FootageDisplay&) = delete;

  /// Draws `frame` with what the tracker did on it (`step`) and `status` (a live status line, or
  /// ""), polls the keys (blocks while paused). Returns false once the viewer pressed q.
  bool show(const runtime::Frame& frame, const scenarios::pan_tilt::FootageStep& step, const std::string& status);
  /// After the run: waits for a click or a key (at once when the viewer quit).
  void close();

private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace viewline::viz
