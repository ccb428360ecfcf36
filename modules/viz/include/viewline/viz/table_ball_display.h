#pragma once
// Live view of the table-ball scenario (ViSP vpDisplayX; only constructed with --display and an
// X display). Window 1, as [M] Fig. 12: the camera image with the detected table corners, the
// table axes (from the estimated pose), the detected ball circle, the filtered ball centre and
// the N predicted positions projected back into the image. Window 2: a top view of the table
// with the measured (red) and filtered (green) tracks, the true ball (blue) and the set point.
// Keys in the camera window (viz::DisplayControls): space pause, n step, q quit.
//
//   viz::TableBallDisplay view(cfg.table_side, cfg.ball_radius);
//   hooks.on_frame = [&](const scenarios::TableBallFrameView& v) { return view.show(v); };
//   ... run ...
//   view.waitForClose();

#include <deque>
#include <memory>

#include "viewline/scenarios/table_ball/loop.h"

namespace viewline::viz {

/// Live view of the table-ball scenario: camera image with corners, table axes, ball and predictions, and a
/// top view of the tracks.
class TableBallDisplay {
public:
  /// Opens both windows: table side and ball radius in metres, top view of `top_view_px` pixels, the last
  /// `track_length` positions drawn; throws core::InvalidInput without X11.
  TableBallDisplay(double table_side, double ball_radius, int top_view_px = 360, std::size_t track_length = 250);
  ~TableBallDisplay();
  TableBallDisplay(const TableBallDisplay&) = delete;
  TableBallDisplay& operator=(const TableBallDisplay&) = delete;
  /// Draws one frame; false once the person asked to quit.
  bool show(const scenarios::TableBallFrameView& view);
  /// After the run: keeps the windows open until a click or a key (not after a quit).
  void waitForClose();

private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace viewline::viz
