// Frame sources from disk and devices, and viewline's recordings: frames, stamps and the error
// messages a user sees for a bad file or a missing camera.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <string>

#include "viewline/core/error.h"
#include "viewline/io/config.h"
#include "viewline/runtime/file_sources.h"
#include "viewline/runtime/recording.h"
#include "viewline/runtime/source_config.h"
#include "viewline/runtime/stamps.h"
#include "viewline/runtime/v4l2_source.h"

namespace fs = std::filesystem;
using namespace viewline;
using namespace viewline::runtime;

namespace {

const std::string kMire = "/usr/share/visp-images-data/ViSP-images/mire-2/image.%04d.pgm";
const std::string kCube = "/usr/share/visp-images-data/ViSP-images/video/cube.mpeg";

fs::path scratch(const std::string& name) {
  const fs::path p = fs::path(testing::TempDir()) / ("viewline_sources_" + std::to_string(::getpid()) + "_" + name);
  fs::remove_all(p);
  fs::create_directories(p);
  return p;
}

void writeText(const fs::path& p, const std::string& text) { std::ofstream(p) << text; }

/// The message of the InvalidInput `f` throws ("" when it throws none).
template <class F>
std::string errorOf(F&& f) {
  try {
    f();
  } catch (const core::InvalidInput& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(FramePattern, FillsOneIntegerConversion) {
  EXPECT_EQ(formatFramePattern("image.%04d.pgm", 7), "image.0007.pgm");
  EXPECT_EQ(formatFramePattern("f%d.png", 123), "f123.png");
  EXPECT_EQ(formatFramePattern("100%%/f%3d.png", 5), "100%/f  5.png");
  EXPECT_NE(errorOf([] { formatFramePattern("image.pgm", 1); }).find("exactly one"), std::string::npos);
  EXPECT_NE(errorOf([] { formatFramePattern("%d_%d.pgm", 1); }).find("exactly one"), std::string::npos);
  EXPECT_NE(errorOf([] { formatFramePattern("%s.pgm", 1); }).find("only one integer conversion"), std::string::npos);
}

TEST(Stamps, ParsesHeaderCommentsAndLines) {
  const auto s = parseStamps("index,stamp\n# from the camera\n1,0.5\n2,0.54\r\n\n4,0.62\n", "s.csv");
  ASSERT_EQ(s.size(), 3u);
  EXPECT_EQ(s[2].index, 4);
  EXPECT_DOUBLE_EQ(s[2].stamp, 0.62);
}

TEST(Stamps, BadLinesNameFileAndLine) {
  EXPECT_NE(errorOf([] { parseStamps("1,0.5\n2,abc\n", "s.csv"); }).find("s.csv:2: stamp: expected a finite number, got 'abc'"),
            std::string::npos);
  EXPECT_NE(errorOf([] { parseStamps("1,0.5\n2,0.5\n", "s.csv"); }).find("s.csv:2: stamp 0.5 does not increase"),
            std::string::npos);
  EXPECT_NE(errorOf([] { parseStamps("3,0.5\n2,0.6\n", "s.csv"); }).find("s.csv:2: index 2 does not increase"),
            std::string::npos);
  EXPECT_NE(errorOf([] { parseStamps("1,0.5,3\n", "s.csv"); }).find("s.csv:1: expected 2 columns"), std::string::npos);
  EXPECT_NE(errorOf([] { parseStamps("1x,0.5\n", "s.csv"); }).find("s.csv:1: index: expected an integer"), std::string::npos);
  EXPECT_NE(errorOf([] { parseStamps("1,nan\n", "s.csv"); }).find("s.csv:1: stamp"), std::string::npos);
  EXPECT_NE(errorOf([] { parseStamps("# nothing\n", "s.csv"); }).find("s.csv: no 'index,stamp' line"), std::string::npos);
  EXPECT_NE(errorOf([] { readStampsFile("/nonexistent/s.csv"); }).find("/nonexistent/s.csv"), std::string::npos);
}

TEST(ImageSequenceSource, ReadsMire2WithRateStamps) {
  if (!fs::exists(formatFramePattern(kMire, 1))) GTEST_SKIP() << "visp-images-data not installed";
  ImageSequenceSource src({kMire, 1, 25.0, "", 5});
  int n = 0;
  while (const auto t = src.nextReadyTime()) {
    const auto f = src.grab();
    ASSERT_TRUE(f);
    EXPECT_EQ(f->sequence, static_cast<std::uint64_t>(n));
    EXPECT_DOUBLE_EQ(f->stamp, n / 25.0);
    EXPECT_DOUBLE_EQ(*t, f->stamp);
    EXPECT_EQ(f->image.type(), CV_8UC1);
    EXPECT_EQ(f->image.cols, 384);
    EXPECT_EQ(f->image.rows, 288);
    ++n;
  }
  EXPECT_EQ(n, 5);
  EXPECT_FALSE(src.grab());
}

TEST(ImageSequenceSource, EndsAtTheFirstMissingFileAndUsesAStampsFile) {
  const fs::path d = scratch("seq");
  const cv::Mat img(8, 8, CV_8UC3, cv::Scalar(1, 2, 3));
  for (int i = 3; i <= 5; ++i) cv::imwrite((d / formatFramePattern("f%02d.png", i)).string(), img);
  ImageSequenceSource by_rate({(d / "f%02d.png").string(), 3, 10.0, "", -1});
  int n = 0;
  while (by_rate.grab()) ++n;
  EXPECT_EQ(n, 3);

  writeText(d / "stamps.csv", "index,stamp\n3,10.0\n5,10.25\n");
  ImageSequenceSource by_file({(d / "f%02d.png").string(), 0, 30.0, (d / "stamps.csv").string(), -1});
  EXPECT_EQ(by_file.stampMethod(), "stamps file " + (d / "stamps.csv").string());
  ASSERT_EQ(*by_file.nextReadyTime(), 10.0);
  by_file.grab();
  const auto second = by_file.grab();
  ASSERT_TRUE(second);
  EXPECT_EQ(second->stamp, 10.25);
  EXPECT_EQ(second->image.type(), CV_8UC3);
  EXPECT_FALSE(by_file.nextReadyTime());
}

TEST(ImageSequenceSource, ErrorsNameTheFile) {
  const fs::path d = scratch("seq_bad");
  const std::string missing = errorOf([&] { ImageSequenceSource({(d / "image.%04d.pgm").string(), 1, 25.0, "", -1}); });
  EXPECT_NE(missing.find((d / "image.0001.pgm").string() + " does not exist"), std::string::npos) << missing;
  writeText(d / "image.0001.pgm", "P5 not really an image");
  ImageSequenceSource src({(d / "image.%04d.pgm").string(), 1, 25.0, "", -1});
  const std::string corrupt = errorOf([&] { src.grab(); });
  EXPECT_NE(corrupt.find((d / "image.0001.pgm").string() + " cannot be decoded"), std::string::npos) << corrupt;
  writeText(d / "stamps.csv", "1,0.1\n2,zero\n");
  const std::string stamps =
      errorOf([&] { ImageSequenceSource({(d / "image.%04d.pgm").string(), 1, 25.0, (d / "stamps.csv").string(), -1}); });
  EXPECT_NE(stamps.find((d / "stamps.csv").string() + ":2: stamp"), std::string::npos) << stamps;
}

TEST(VideoSource, DecodesCubeMpegEveryPicture) {
  if (!fs::exists(kCube)) GTEST_SKIP() << "visp-images-data not installed";
  // The reference count, independent of FFmpeg: cube.mpeg is an MPEG-1 elementary video stream,
  // one picture start code (00 00 01 00, ISO/IEC 11172-2 §2.4.2) per picture.
  const std::string bytes = csv::readWholeFile(kCube, "video");
  std::size_t pictures = 0;
  for (std::size_t i = 0; i + 3 < bytes.size(); ++i)
    if (bytes[i] == 0 && bytes[i + 1] == 0 && bytes[i + 2] == 1 && bytes[i + 3] == 0) ++pictures;
  ASSERT_EQ(pictures, 79u);

  VideoSource src({kCube, "", -1});
  // No system layer, so no presentation times: the nominal 25 Hz.
  EXPECT_EQ(src.stampMethod().rfind("nominal rate 25", 0), 0u) << src.stampMethod();
  std::size_t n = 0;
  double last = -1.0;
  while (src.nextReadyTime()) {
    const auto f = src.grab();
    ASSERT_TRUE(f);
    EXPECT_GT(f->stamp, last);
    EXPECT_EQ(f->image.size(), cv::Size(384, 288));
    EXPECT_EQ(f->image.type(), CV_8UC3);
    last = f->stamp;
    ++n;
  }
  EXPECT_EQ(n, pictures);
  EXPECT_DOUBLE_EQ(last, 78 / 25.0);
}

TEST(VideoSource, StampsFileMustCoverEveryFrame) {
  if (!fs::exists(kCube)) GTEST_SKIP() << "visp-images-data not installed";
  const fs::path d = scratch("video_stamps");
  writeText(d / "s.csv", "0,1.0\n1,1.5\n");
  VideoSource src({kCube, (d / "s.csv").string(), -1});
  EXPECT_EQ(src.grab()->stamp, 1.0);
  const std::string e = errorOf([&] { src.grab(); });  // decoding frame 2 finds no stamp
  EXPECT_NE(e.find("frame 2 has no line in " + (d / "s.csv").string()), std::string::npos) << e;
}

TEST(VideoSource, ErrorsNameTheFile) {
  const fs::path d = scratch("video_bad");
  EXPECT_NE(errorOf([&] { VideoSource({(d / "none.mp4").string(), "", -1}); }).find((d / "none.mp4").string() + " does not exist"),
            std::string::npos);
  writeText(d / "text.mp4", "not a video at all\n");
  const std::string bad = errorOf([&] { VideoSource({(d / "text.mp4").string(), "", -1}); });
  EXPECT_NE(bad.find((d / "text.mp4").string()), std::string::npos) << bad;
}

TEST(V4l2Source, MissingDeviceAndNonDeviceFailNamingTheDevice) {
  if (fs::exists("/dev/video99")) GTEST_SKIP() << "/dev/video99 exists on this machine";
  V4l2Options o;
  o.device = "/dev/video99";
  const std::string missing = errorOf([&] { V4l2Source s(o); });
  EXPECT_NE(missing.find("v4l2 camera /dev/video99: no such device"), std::string::npos) << missing;
  const fs::path d = scratch("v4l2");
  writeText(d / "video0", "");
  o.device = (d / "video0").string();
  const std::string file = errorOf([&] { V4l2Source s(o); });
  EXPECT_NE(file.find("v4l2 camera " + o.device + ": not a V4L2 device"), std::string::npos) << file;
  o.device = "/dev/null";  // a character device that is no camera
  const std::string null = errorOf([&] { V4l2Source s(o); });
  EXPECT_NE(null.find("v4l2 camera /dev/null: cannot be opened as a V4L2 capture device"), std::string::npos) << null;
}

TEST(Recording, WritesAndReadsBackBitForBit) {
  const fs::path d = scratch("rec");
  cv::Mat grey(6, 9, CV_8UC1), bgr(5, 7, CV_8UC3);
  cv::randu(grey, 0, 256);
  cv::randu(bgr, 0, 256);
  {
    RecordingWriter w((d / "r").string());
    core::Camera cam;
    cam.intrinsics.initPersProjWithDistortion(600.0, 610.0, 320.5, 240.25, -0.1, 0.1);
    cam.width = 640;
    cam.height = 480;
    w.setCamera(0, cam);
    w.setConfig("a: 1\n");
    w.setTruthColumns({"x", "y"});
    Frame f;
    f.sequence = 0;
    f.capture_time = 0.1 / 3.0;
    f.stamp = 0.1 / 3.0 + 1e-17;
    f.image = grey;
    w.frame(0.05, f);
    w.truth(0, 0, {1.0 / 3.0, -2.0 / 7.0});
    w.lost(0.1);
    f.sequence = 2;
    f.capture_time = 0.2 / 3.0;
    f.stamp = 0.2 / 3.0;
    f.image = bgr;
    w.frame(0.12, f);
    Frame known;  // a lost frame whose times the source knew
    known.sequence = 3;
    known.capture_time = 0.3;
    known.stamp = 0.31;
    w.lost(0.15, known);
    w.finish();
    EXPECT_NE(errorOf([&] { RecordingWriter again((d / "r").string()); }).find("already holds a recording"), std::string::npos);
  }
  RecordingSource r((d / "r").string());
  ASSERT_TRUE(r.hasTruth());
  EXPECT_EQ(*r.nextReadyTime(), 0.05);
  auto a = r.grab();
  ASSERT_TRUE(a);
  EXPECT_EQ(a->capture_time, 0.1 / 3.0);
  EXPECT_EQ(a->stamp, 0.1 / 3.0 + 1e-17);
  EXPECT_EQ(cv::countNonZero(a->image != grey), 0);
  EXPECT_EQ(r.truth(0, 0)->at(1), -2.0 / 7.0);
  EXPECT_EQ(*r.nextReadyTime(), 0.1);
  EXPECT_FALSE(r.grab());  // the lost grab
  auto b = r.grab();
  ASSERT_TRUE(b);
  EXPECT_EQ(b->sequence, 2u);
  EXPECT_EQ(b->image.type(), CV_8UC3);
  EXPECT_EQ(cv::norm(b->image, bgr, cv::NORM_INF), 0.0);
  EXPECT_FALSE(r.grab());
  EXPECT_TRUE(r.lastEntry() == &r.entries().back());
  EXPECT_EQ(r.entries().back().sequence, 3u);
  EXPECT_EQ(r.entries().back().stamp, 0.31);
  EXPECT_TRUE(r.entries().back().file.empty());
  EXPECT_FALSE(r.nextReadyTime());
  const auto cam = r.camera(0);
  ASSERT_TRUE(cam);
  EXPECT_EQ(cam->intrinsics.get_px(), 600.0);
  EXPECT_EQ(cam->intrinsics.get_kud(), -0.1);
  EXPECT_EQ(r.configText(), "a: 1\n");
}

TEST(Recording, PerFrameTablesReadBackBitForBit) {
  const fs::path d = scratch("rec_table");
  {
    RecordingWriter w((d / "r").string());
    w.setTable("ptu", {"joint_t", "pan"});
    EXPECT_NE(errorOf([&] { w.setTable("ptu", {"x"}); }).find("declared twice"), std::string::npos);
    EXPECT_NE(errorOf([&] { w.setTable("truth", {"x"}); }).find("table name"), std::string::npos);
    EXPECT_NE(errorOf([&] { w.setTable("../up", {"x"}); }).find("table name"), std::string::npos);
    EXPECT_NE(errorOf([&] { w.tableRow("other", 0, 0, {1.0}); }).find("not declared"), std::string::npos);
    EXPECT_NE(errorOf([&] { w.tableRow("ptu", 0, 0, {1.0}); }).find("1 values for the 2 columns"), std::string::npos);
    Frame f;
    f.sequence = 4;
    f.capture_time = f.stamp = 0.1 / 3.0;
    f.image = cv::Mat(4, 4, CV_8UC1, cv::Scalar(7));
    w.frame(0.05, f);
    w.tableRow("ptu", 0, 4, {0.1 / 3.0, -1.0 / 7.0});
    w.finish();
    EXPECT_NE(errorOf([&] { w.tableRow("ptu", 0, 5, {0.0, 0.0}); }).find("after finish()"), std::string::npos);
  }
  const RecordingSource r((d / "r").string());
  EXPECT_FALSE(r.hasTruth());
  EXPECT_FALSE(r.table("other"));
  const auto t = r.table("ptu");
  ASSERT_TRUE(t);
  EXPECT_EQ(t->columns, (std::vector<std::string>{"joint_t", "pan"}));
  ASSERT_EQ(t->rows.size(), 1u);
  EXPECT_EQ(t->rows.at({0, 4}), (std::vector<double>{0.1 / 3.0, -1.0 / 7.0}));
}

TEST(Recording, IndexErrorsNameFileAndLine) {
  const std::string h = "ready_time,camera,sequence,capture_time,stamp,file\n";
  EXPECT_NE(errorOf([] { parseRecordingIndex("time,file\n", "r.csv"); }).find("r.csv:1: expected the header"), std::string::npos);
  EXPECT_NE(errorOf([&] { parseRecordingIndex(h + "0.1,0,0,0.1,0.1,../x.png\n", "r.csv"); }).find("r.csv:2: file '../x.png'"),
            std::string::npos);
  EXPECT_NE(errorOf([&] { parseRecordingIndex(h + "0.2,0,0,0.1,0.1,a.png\n0.1,0,1,0.1,0.1,b.png\n", "r.csv"); })
                .find("r.csv:3: ready_time 0.1 is before"),
            std::string::npos);
  EXPECT_NE(errorOf([&] { parseRecordingIndex(h + "0.1,0,1,0.1,0.1,a.png\n0.2,0,1,0.1,0.1,b.png\n", "r.csv"); })
                .find("r.csv:3: sequence 1 of camera 0 does not increase"),
            std::string::npos);
  EXPECT_NE(errorOf([&] { parseRecordingIndex(h + "0.1,0,0,x,0.1,a.png\n", "r.csv"); }).find("r.csv:2: capture_time"),
            std::string::npos);
  EXPECT_NE(errorOf([] { parseRecordingTruth("camera,sequence,x\n0,0,1\n0,0,2\n", "t.csv"); }).find("t.csv:3: a second truth row"),
            std::string::npos);
  EXPECT_NE(errorOf([] { RecordingSource s("/nonexistent/rec"); }).find("/nonexistent/rec does not exist"), std::string::npos);
}

TEST(SourceConfig, ReadsEachKindAndRefusesOtherKindsKeys) {
  const auto read = [](const std::string& yaml) { return readSourceConfig(io::ConfigNode::fromString(yaml, "s.yaml", "/cfg")); };
  EXPECT_TRUE(read("a: 1\n").simulated());
  const SourceConfig img = read("source: {kind: images, pattern: seq/image.%04d.pgm, first: 1, rate_hz: 25}\n");
  EXPECT_EQ(img.kind, SourceKind::Images);
  EXPECT_EQ(img.images.pattern, "/cfg/seq/image.%04d.pgm");
  EXPECT_EQ(img.images.first, 1);
  EXPECT_EQ(read("source: {kind: recording, path: /r}\n").recording, "/r");
  EXPECT_NE(errorOf([&] { read("source: {kind: images, pattern: seq/image.pgm}\n"); }).find("exactly one"), std::string::npos);
  const io::ConfigNode n = io::ConfigNode::fromString("source: {kind: video, path: a.mp4, device: /dev/video0}\n", "s.yaml");
  readSourceConfig(n);
  EXPECT_NE(errorOf([&] { n.finish(); }).find("source.device"), std::string::npos);
  EXPECT_NE(errorOf([&] { read("source: {kind: webcam}\n"); }).find("source.kind"), std::string::npos);
}
