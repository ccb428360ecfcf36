// Tracks a bright disc through footage: an image sequence or a video (runtime::ImageSequenceSource,
// runtime::VideoSource), [T]'s disc detector in a window placed by the pan-tilt target filter
// (scenarios::pan_tilt::FootageTracker), optionally against ViSP's vpDot2 on the same frames.
//
//   track_footage --images /usr/share/visp-images-data/ViSP-images/mire-2/image.%04d.pgm
//                 --first 1 --rate 25 --start 160 212 --vpdot2 --csv track.csv
//   track_footage --video clip.mp4 --start 320 240
//   track_footage --video clip.mp4 --start 320 240 --pace [--display]   # as a live camera
//
// --pace plays the footage as a live camera at its stamps' rate (runtime::PacedSource): frames
// that arrive while a frame is processed are dropped and counted, and each frame's processing
// time is reported against a deadline of one frame period (--deadline-ms to change it).
#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <iostream>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "viewline/core/error.h"
#include "viewline/core/statistics.h"
#include "viewline/io/files.h"
#include "viewline/runtime/file_sources.h"
#include "viewline/runtime/live.h"
#include "viewline/runtime/stamps.h"
#include "viewline/scenarios/pan_tilt/footage.h"
#include "viewline/viz/footage_display.h"

namespace {

/// The frame rate of a stamps file: 1 / the median interval between its stamps, Hz (0: fewer than two).
double stampsRate(const std::string& file) {
  const auto stamps = viewline::runtime::readStampsFile(file);
  std::vector<double> dt;
  for (std::size_t i = 1; i < stamps.size(); ++i) dt.push_back(stamps[i].stamp - stamps[i - 1].stamp);
  return dt.empty() ? 0.0 : 1.0 / viewline::core::percentile(dt, 0.5);
}

}  // namespace

using namespace viewline;

int main(int argc, char** argv) {
  CLI::App cli{"track a bright disc through an image sequence or a video (viewline tutorial)"};
  std::string images, video, stamps, csv;
  std::vector<double> start;
  bool vpdot2 = false;
  double rate = 30.0;
  long long first = 0, count = -1;
  auto* img_opt = cli.add_option("--images", images, "printf pattern of the image files (image.%04d.pgm)");
  auto* vid_opt = cli.add_option("--video", video, "a video file (FFmpeg)");
  img_opt->excludes(vid_opt);
  cli.add_option("--first", first, "images: index of the first file");
  cli.add_option("--rate", rate, "images: frames per second without --stamps");
  cli.add_option("--stamps", stamps, "index,stamp CSV of the frames' time stamps");
  cli.add_option("--count", count, "at most this many frames");
  cli.add_option("--start", start, "the disc's centre in the first frame: U V (px)")->expected(2)->required();
  cli.add_flag("--vpdot2", vpdot2, "also track with ViSP's vpDot2 and compare the centres");
  cli.add_option("--csv", csv, "per-frame centres into this CSV (t,detected,u,v,pred_u,pred_v)");
  double pace = -1.0, deadline_ms = 0.0;
  bool display = false;
  cli.add_option("--pace", pace,
                 "play the footage as a live camera at FACTOR times its stamps' rate (1 without a value): frames "
                 "that arrive while one is processed are dropped and counted")
      ->expected(0, 1)
      ->default_str("1")
      ->check(CLI::Range(0.0, 100.0));
  cli.add_option("--deadline-ms", deadline_ms, "with --pace: a frame's processing deadline, ms (default: one frame period)")
      ->check(CLI::PositiveNumber);
  cli.add_flag("--display", display, "show each frame with the window, detection, prediction and image centre");
  double slow_ms = 0.0;
  cli.add_option("--slow-ms", slow_ms,
                 "add this much waiting to each frame's processing, ms (what a slower tracker would miss with --pace)")
      ->check(CLI::NonNegativeNumber);
  try {
    cli.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return cli.exit(e) == 0 ? 0 : 2;
  }
  if (images.empty() == video.empty()) {
    std::cerr << "track_footage: give --images PATTERN or --video FILE\n";
    return 2;
  }
  if (deadline_ms > 0.0 && pace < 0.0) {
    std::cerr << "track_footage: --deadline-ms needs --pace\n";
    return 2;
  }
  try {
    std::unique_ptr<runtime::FrameSource> source;
    double footage_rate = 0.0;  // Hz: the footage's frame rate (the deadline's default is one period)
    if (!images.empty()) {
      source = std::make_unique<runtime::ImageSequenceSource>(runtime::ImageSequenceOptions{images, first, rate, stamps, count});
      footage_rate = stamps.empty() ? rate : stampsRate(stamps);
    } else {
      auto v = std::make_unique<runtime::VideoSource>(runtime::VideoOptions{video, stamps, count});
      footage_rate = stamps.empty() ? v->nominalRate() : stampsRate(stamps);
      source = std::move(v);
    }
    scenarios::pan_tilt::FootageRunOptions run;
    run.vpdot2 = vpdot2;
    if (pace >= 0.0) {
      const double factor = pace > 0.0 ? pace : 1.0;  // --pace without a value
      source = std::make_unique<runtime::PacedSource>(std::move(source), factor, images.empty() ? "video " + video
                                                                                                 : "images " + images);
      char origin[96];
      if (deadline_ms > 0.0) {
        run.deadline_s = 1e-3 * deadline_ms;
        std::snprintf(origin, sizeof origin, "--deadline-ms");
      } else {
        if (!(footage_rate > 0.0))
          throw core::InvalidInput("--pace: the footage has no frame rate to take the deadline from; give --deadline-ms");
        run.deadline_s = 1.0 / (footage_rate * factor);
        std::snprintf(origin, sizeof origin, "one frame period at %g fps", footage_rate * factor);
      }
      run.deadline_origin = origin;
    }
    std::unique_ptr<viz::FootageDisplay> view;
    if (display) view = std::make_unique<viz::FootageDisplay>();
    if (view || slow_ms > 0.0)
      run.on_frame = [&](const runtime::Frame& f, const scenarios::pan_tilt::FootageStep& step, const std::string& status) {
        if (slow_ms > 0.0) std::this_thread::sleep_for(std::chrono::duration<double, std::milli>(slow_ms));
        return view ? view->show(f, step, status) : true;
      };
    const auto r = scenarios::pan_tilt::trackFootage(
        *source, scenarios::pan_tilt::brightDiscTrackerConfig({start[0], start[1]}), run);
    if (view) view->close();
    std::printf("%zu frames, %zu lost\n", r.frames, r.lost);
    if (r.live) {
      std::printf("%s\n", runtime::summaryLine(*r.live).c_str());
      std::printf("%s\n", runtime::processingLine(*r.live).c_str());
    }
    if (vpdot2) std::printf("vpDot2: %zu frames compared, rms %.3f px, max %.3f px\n", r.compared, r.vpdot2_rms_px, r.vpdot2_max_px);
    std::printf("one frame ahead (%zu frames): filter rms %.3f px, hold-last rms %.3f px, ratio %.3f\n", r.predicted,
                r.predicted_rms_px, r.hold_rms_px, r.predicted_rms_px / r.hold_rms_px);
    if (!csv.empty()) {
      std::string text = "t,detected,u,v,pred_u,pred_v\n";
      char line[200];
      for (const auto& s : r.steps) {
        std::snprintf(line, sizeof line, "%.6f,%d,%.3f,%.3f,%.3f,%.3f\n", s.stamp, s.detected ? 1 : 0, s.measured_px.x(),
                      s.measured_px.y(), s.has_prediction ? s.predicted_px.x() : std::nan(""),
                      s.has_prediction ? s.predicted_px.y() : std::nan(""));
        text += line;
      }
      io::writeTextFileAtomic(csv, text);
    }
    return r.lost == 0 ? 0 : 1;
  } catch (const core::Error& e) {
    std::cerr << "track_footage: " << e.what() << "\n";
    return 1;
  }
}
