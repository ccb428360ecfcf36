#pragma once
// What every scenario window does besides drawing: the keys a person watching a run needs, and
// staying open at the end (ViSP's examples end with vpDisplay::getClick() for the same reason).
//
//   space        pause / resume
//   n            one frame forward while paused
//   q or Escape  quit: the run ends early (its partial summary is still written)
//
//   viz::DisplayControls controls;
//   ... vpDisplay::flush(I);
//   if (!controls.poll(I)) scheduler.requestStop();   // after each frame
//   ...
//   controls.waitForClose(I);                           // after the run
//
// The legend is drawn by drawLegend(I) before the flush. With no X display nothing here blocks.

#include <string>
#include <visp3/core/vpImage.h>
#include <visp3/core/vpRGBa.h>

namespace viewline::viz {

/// Keys of every scenario window (space pause, n step, q quit) and staying open after the run.
class DisplayControls {
public:
  /// Polls the keyboard of the window showing I (no wait). While paused, waits for a key:
  /// space resumes, n returns after one frame, q/Escape quits. Returns false once quit was asked.
  bool poll(const vpImage<vpRGBa>& I);
  /// Draws "space pause  n step  q quit" (and "paused" while paused) at the bottom of I.
  void drawLegend(const vpImage<vpRGBa>& I) const;
  /// After the run: says so in the window and waits for a click or a key (returns at once when
  /// quit was already asked).
  void waitForClose(const vpImage<vpRGBa>& I) const;

  /// True while the viewer has paused the run (space).
  bool paused() const { return paused_; }
  /// True once the viewer pressed q or Escape: the run should stop.
  bool quitRequested() const { return quit_; }

private:
  bool handle(const std::string& key);
  bool paused_ = false;
  bool quit_ = false;
};

}  // namespace viewline::viz
