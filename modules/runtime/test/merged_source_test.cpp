// One source per camera merged in stamp order (runtime/merged_source.h): the order of the frames
// over the cameras, the tie rule, the per-camera counts, and the messages naming a camera's bad
// footage (a missing file, a frame of the wrong size or not in colour).
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "viewline/core/error.h"
#include "viewline/runtime/merged_source.h"

namespace fs = std::filesystem;
using namespace viewline;
using namespace viewline::runtime;

namespace {

// Camera `name`'s image sequence in `dir`: one w x h frame per stamp, with its stamps file.
MergedCamera writeCamera(const fs::path& dir, const std::string& name, const std::vector<double>& stamps, int w = 8,
                         int h = 6, int type = CV_8UC3) {
  fs::create_directories(dir / name);
  std::ofstream csv(dir / name / "stamps.csv");
  csv << "index,stamp\n";
  for (std::size_t i = 0; i < stamps.size(); ++i) {
    char file[32];
    std::snprintf(file, sizeof file, "%04zu.png", i);
    EXPECT_TRUE(cv::imwrite((dir / name / file).string(), cv::Mat(h, w, type, cv::Scalar::all(40))));
    csv << i << "," << stamps[i] << "\n";
  }
  MergedCamera c;
  c.name = name;
  c.source.kind = SourceKind::Images;
  c.source.images.pattern = (dir / name / "%04d.png").string();
  c.source.images.stamps_file = (dir / name / "stamps.csv").string();
  c.width = 8;
  c.height = 6;
  return c;
}

template <class F>
std::string errorOf(F&& f) {
  try {
    f();
  } catch (const core::InvalidInput& e) {
    return e.what();
  }
  return "";
}

fs::path scratch(const std::string& name) {
  const fs::path p = fs::path(testing::TempDir()) / ("viewline_merged_" + std::to_string(::getpid()) + "_" + name);
  fs::remove_all(p);
  return p;
}

}  // namespace

TEST(MergedFrameSource, HandsOutTheCamerasFramesInStampOrderTiesToTheLowerIndex) {
  const fs::path dir = scratch("order");
  const std::vector<MergedCamera> cams = {writeCamera(dir, "a", {0.00, 0.02, 0.04}),
                                          writeCamera(dir, "b", {0.01, 0.02, 0.05, 0.07})};
  MergedFrameSource merged(cams);
  ASSERT_EQ(merged.cameraCount(), 2u);
  EXPECT_EQ(merged.sourceName(0), "images " + cams[0].source.images.pattern);
  std::vector<std::pair<std::size_t, double>> got;
  while (merged.nextReadyTime()) {
    const auto f = merged.grab();
    ASSERT_TRUE(f.has_value());
    got.emplace_back(f->camera, f->stamp);
  }
  const std::vector<std::pair<std::size_t, double>> want = {{0, 0.00}, {1, 0.01}, {0, 0.02}, {1, 0.02},
                                                            {0, 0.04}, {1, 0.05}, {1, 0.07}};
  EXPECT_EQ(got, want);
  EXPECT_EQ(merged.frames(0), 3u);
  EXPECT_EQ(merged.frames(1), 4u);
  EXPECT_EQ(merged.lost(0) + merged.lost(1), 0u);
  EXPECT_EQ(merged.delivered(), 7u);
  EXPECT_FALSE(merged.live());
  fs::remove_all(dir);
}

TEST(MergedFrameSource, NamesTheCameraOfAMissingFileOrABadFrame) {
  const fs::path dir = scratch("bad");
  MergedCamera missing = writeCamera(dir, "a", {0.0});
  missing.name = "left";
  missing.source.images.pattern = (dir / "none" / "%04d.png").string();
  const std::string e = errorOf([&] { MergedFrameSource m({missing}); });
  EXPECT_NE(e.find("cameras[left].source"), std::string::npos) << e;
  EXPECT_NE(e.find((dir / "none" / "0000.png").string()), std::string::npos) << e;

  MergedFrameSource small({writeCamera(dir, "small", {0.0}, 4, 6)});
  const std::string s = errorOf([&] { small.grab(); });
  EXPECT_NE(s.find("cameras[small].source"), std::string::npos) << s;
  EXPECT_NE(s.find("4x6 px, the camera's calibration is 8x6 px"), std::string::npos) << s;

  MergedFrameSource grey({writeCamera(dir, "grey", {0.0}, 8, 6, CV_8UC1)});
  const std::string g = errorOf([&] { grey.grab(); });
  EXPECT_NE(g.find("not a colour"), std::string::npos) << g;

  MergedCamera sim;
  sim.name = "s";
  EXPECT_NE(errorOf([&] { MergedFrameSource m({sim}); }).find("expected footage"), std::string::npos);
  fs::remove_all(dir);
}
