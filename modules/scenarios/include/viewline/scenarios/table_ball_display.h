#pragma once
// Live view of the table-ball scenario (ViSP vpDisplayX; only constructed with --display and an
// X display). Window 1, as [M] Fig. 12: the camera image with the detected table corners, the
// table axes (from the estimated pose), the detected ball circle, the filtered ball centre and
// the N predicted positions projected back into the image. Window 2: a top view of the table
// with the measured (red) and filtered (green) tracks, the true ball (blue) and the set point.

#include <deque>
#include <memory>

#include "viewline/scenarios/table_ball.h"

namespace viewline::scenarios {

class TableBallDisplay {
public:
  TableBallDisplay(double table_side, double ball_radius, int top_view_px = 360, std::size_t track_length = 250);
  ~TableBallDisplay();
  TableBallDisplay(const TableBallDisplay&) = delete;
  TableBallDisplay& operator=(const TableBallDisplay&) = delete;
  void show(const TableBallFrameView& view);

private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace viewline::scenarios
