// Tracks a bright disc through footage: an image sequence or a video (runtime::ImageSequenceSource,
// runtime::VideoSource), [T]'s disc detector in a window placed by the pan-tilt target filter
// (scenarios::pan_tilt::FootageTracker), optionally against ViSP's vpDot2 on the same frames.
//
//   track_footage --images /usr/share/visp-images-data/ViSP-images/mire-2/image.%04d.pgm
//                 --first 1 --rate 25 --start 160 212 --vpdot2 --csv track.csv
//   track_footage --video clip.mp4 --start 320 240
#include <CLI/CLI.hpp>
#include <cstdio>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "viewline/core/error.h"
#include "viewline/io/files.h"
#include "viewline/runtime/source_config.h"
#include "viewline/scenarios/pan_tilt/footage.h"

using namespace viewline;

int main(int argc, char** argv) {
  CLI::App cli{"track a bright disc through an image sequence or a video (viewline tutorial)"};
  runtime::SourceConfig src;
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
  try {
    cli.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return cli.exit(e) == 0 ? 0 : 2;
  }
  if (images.empty() == video.empty()) {
    std::cerr << "track_footage: give --images PATTERN or --video FILE\n";
    return 2;
  }
  try {
    if (!images.empty()) {
      src.kind = runtime::SourceKind::Images;
      src.images = {images, first, rate, stamps, count};
    } else {
      src.kind = runtime::SourceKind::Video;
      src.video = {video, stamps, count};
    }
    const std::unique_ptr<runtime::FrameSource> source = runtime::makeFrameSource(src);
    const auto r = scenarios::pan_tilt::trackFootage(
        *source, scenarios::pan_tilt::brightDiscTrackerConfig({start[0], start[1]}), vpdot2);
    std::printf("%zu frames, %zu lost\n", r.frames, r.lost);
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
