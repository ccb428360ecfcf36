#include "viewline/viz/display_controls.h"

#include <string>
#include <visp3/core/vpDisplay.h>
#include <visp3/core/vpTime.h>

namespace viewline::viz {

namespace {
bool hasDisplay(const vpImage<vpRGBa>& I) { return I.display != nullptr; }
}  // namespace

bool DisplayControls::handle(const std::string& key) {
  if (key == "q" || key == "Q" || key == "\x1b" || key == "Escape") {
    quit_ = true;
    paused_ = false;
    return true;
  }
  if (key == " " || key == "space") {
    paused_ = !paused_;
    return true;
  }
  if (key == "n" || key == "N") return paused_;  // one step: leave the wait
  return false;
}

bool DisplayControls::poll(const vpImage<vpRGBa>& I) {
  if (quit_) return false;
  if (!hasDisplay(I)) return true;
  std::string key;
  if (vpDisplay::getKeyboardEvent(I, key, false)) handle(key);
  while (paused_ && !quit_) {
    key.clear();
    if (vpDisplay::getKeyboardEvent(I, key, false)) {
      const bool was_paused = paused_;
      if (handle(key) && was_paused && paused_) break;  // 'n': one frame, still paused
      continue;
    }
    if (vpDisplay::getClick(I, false)) paused_ = false;
    vpTime::wait(20);
  }
  return !quit_;
}

void DisplayControls::drawLegend(const vpImage<vpRGBa>& I) const {
  if (!hasDisplay(I)) return;
  const int row = static_cast<int>(I.getHeight()) - 10;
  vpDisplay::displayText(I, row, 8, paused_ ? "PAUSED  space resume  n step  q quit" : "space pause  n step  q quit",
                         vpColor::cyan);
}

void DisplayControls::waitForClose(const vpImage<vpRGBa>& I) const {
  if (quit_ || !hasDisplay(I)) return;
  vpDisplay::displayText(I, 14 + 16 * 3, 8, "run finished: click or press a key to close", vpColor::orange);
  vpDisplay::flush(I);
  while (true) {
    if (vpDisplay::getClick(I, false)) return;
    if (vpDisplay::getKeyboardEvent(I, false)) return;
    vpTime::wait(20);
  }
}

}  // namespace viewline::viz
