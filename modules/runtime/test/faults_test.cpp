// The fault-injecting source decorator: each fault kind changes exactly the frames of its camera
// and window, counts them, and leaves every other frame as the inner source made it.
#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include "viewline/core/error.h"
#include "viewline/io/config.h"
#include "viewline/runtime/faults.h"
#include "viewline/runtime/stale_frames.h"

namespace viewline::runtime {
namespace {

// Two cameras at 50 Hz, interleaved (camera 1 half a period after camera 0); each image is
// filled with its frame's sequence number, and the stamp is the capture time plus 1 ms.
class TwoCameras : public FrameSource {
public:
  explicit TwoCameras(int frames_per_camera) : n_(2 * frames_per_camera) {}
  std::size_t cameraCount() const override { return 2; }
  std::optional<core::Timestamp> nextReadyTime() const override {
    if (i_ >= n_) return std::nullopt;
    return time(i_);
  }
  std::optional<Frame> grab() override {
    Frame f;
    f.camera = static_cast<std::size_t>(i_ % 2);
    f.sequence = static_cast<std::uint64_t>(i_ / 2);
    f.capture_time = time(i_);
    f.stamp = f.capture_time + 0.001;
    f.image = cv::Mat(4, 4, CV_8UC1, cv::Scalar(static_cast<double>(f.sequence % 256)));
    ++i_;
    return f;
  }

private:
  static double time(int i) { return 0.01 * i; }  // 0.02 s per camera, 0.01 s apart
  int n_, i_ = 0;
};

std::vector<Frame> drain(FrameSource& s, int* lost = nullptr) {
  std::vector<Frame> out;
  while (s.nextReadyTime()) {
    if (auto f = s.grab()) out.push_back(*f);
    else if (lost) ++*lost;
  }
  return out;
}

TEST(FaultInjectingSource, WithoutFaultsEveryFrameIsTheInnerOne) {
  TwoCameras inner(50), ref(50);
  FaultInjectingSource s(inner, {}, 1);
  const std::vector<Frame> got = drain(s), want = drain(ref);
  ASSERT_EQ(got.size(), want.size());
  for (std::size_t i = 0; i < got.size(); ++i) {
    EXPECT_EQ(got[i].stamp, want[i].stamp);
    EXPECT_EQ(cv::countNonZero(got[i].image != want[i].image), 0);
  }
  EXPECT_EQ(s.counters().touched, 0u);
}

TEST(FaultInjectingSource, FreezeRepeatsTheLastGoodImageOfThatCameraWithNewStamps) {
  TwoCameras inner(50);
  // Camera 0 frames at 0.40, 0.42, ..., 0.58 s (sequence 20-29) frozen: they show sequence 19.
  FaultInjectingSource s(inner, {{FaultKind::Freeze, 0, 0.40, 0.60}}, 1);
  for (const Frame& f : drain(s)) {
    const int shown = f.image.at<unsigned char>(0, 0);
    if (f.camera == 0 && f.sequence >= 20 && f.sequence < 30) {
      EXPECT_EQ(shown, 19) << f.sequence;
    } else {
      EXPECT_EQ(shown, static_cast<int>(f.sequence)) << f.camera << " " << f.sequence;
    }
    EXPECT_DOUBLE_EQ(f.stamp, f.capture_time + 0.001);  // new stamps
  }
  EXPECT_EQ(s.counters().of(FaultKind::Freeze), 10u);
  EXPECT_EQ(s.counters().touched, 10u);
}

TEST(FaultInjectingSource, StampFaultsRepeatOrGoBackFromTheCamerasPreviousStamp) {
  TwoCameras inner(50);
  FaultInjectingSource s(inner, {{FaultKind::StampRepeat, 1, 0.205, 0.25}, {FaultKind::StampBackwards, 0, 0.60, 0.61, 0.005}}, 1);
  double prev1 = -1.0, prev0 = -1.0;
  for (const Frame& f : drain(s)) {
    if (f.camera == 1 && f.capture_time >= 0.205 && f.capture_time < 0.25) {
      EXPECT_DOUBLE_EQ(f.stamp, prev1);  // repeated: the stamp handed out last (also a repeat)
    } else if (f.camera == 0 && f.capture_time >= 0.60 && f.capture_time < 0.61) {
      EXPECT_DOUBLE_EQ(f.stamp, prev0 - 0.005);
      EXPECT_LT(f.stamp, prev0);
    } else {
      EXPECT_DOUBLE_EQ(f.stamp, f.capture_time + 0.001);
    }
    (f.camera == 0 ? prev0 : prev1) = f.stamp;
  }
  // Camera 1 captures at 0.21, 0.23 (odd hundredths); camera 0 at 0.60.
  EXPECT_EQ(s.counters().of(FaultKind::StampRepeat), 2u);
  EXPECT_EQ(s.counters().of(FaultKind::StampBackwards), 1u);
}

TEST(FaultInjectingSource, BlackoutLosesThoseFramesAndTheCameraComesBack) {
  TwoCameras inner(100);
  FaultInjectingSource s(inner, {{FaultKind::Blackout, 1, 1.0, 1.5}}, 1);
  int lost = 0;
  const std::vector<Frame> got = drain(s, &lost);
  EXPECT_EQ(lost, 25);  // camera 1 at 1.01, 1.03, ..., 1.49
  EXPECT_EQ(s.counters().of(FaultKind::Blackout), 25u);
  bool after = false;
  for (const Frame& f : got) {
    EXPECT_FALSE(f.camera == 1 && f.capture_time >= 1.0 && f.capture_time < 1.5);
    after = after || (f.camera == 1 && f.capture_time >= 1.5);
  }
  EXPECT_TRUE(after);  // it came back
}

TEST(FaultInjectingSource, CorruptImagesAreSeededNoiseOnEveryCameraWithoutACameraIndex) {
  auto run = [](std::uint64_t seed) {
    TwoCameras inner(20);
    FaultInjectingSource s(inner, {{FaultKind::Corrupt, std::nullopt, 0.1, 0.14}}, seed);
    std::vector<Frame> frames = drain(s);
    EXPECT_EQ(s.counters().of(FaultKind::Corrupt), 4u);  // 0.10, 0.11, 0.12, 0.13
    return frames;
  };
  const std::vector<Frame> a = run(7), b = run(7), c = run(8);
  int corrupted = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(cv::countNonZero(a[i].image != b[i].image), 0);  // same seed, same garbage
    if (a[i].capture_time >= 0.1 && a[i].capture_time < 0.14) {
      ++corrupted;
      EXPECT_GT(cv::countNonZero(a[i].image != c[i].image), 0);
    }
  }
  EXPECT_EQ(corrupted, 4);
}

TEST(FaultInjectingSource, RefusesBadWindowsAndCameras) {
  TwoCameras inner(5);
  EXPECT_THROW(FaultInjectingSource(inner, {{FaultKind::Freeze, 0, 1.0, 1.0}}, 1), core::InvalidInput);
  EXPECT_THROW(FaultInjectingSource(inner, {{FaultKind::Freeze, 2, 0.0, 1.0}}, 1), core::InvalidInput);
  EXPECT_THROW(FaultInjectingSource(inner, {{FaultKind::StampBackwards, 0, 0.0, 1.0, 0.0}}, 1), core::InvalidInput);
}

TEST(FaultConfig, ReadsTheListAndNamesTheBadKey) {
  const io::ConfigNode root = io::ConfigNode::fromString(
      "faults:\n"
      "  - {kind: freeze, camera: 0, from_s: 2.0, to_s: 2.2}\n"
      "  - {kind: stamp_backwards, from_s: 4.0, to_s: 4.05, step_s: 0.02}\n",
      "faults.yaml");
  const std::vector<FaultSpec> f = readFaultConfig(root);
  ASSERT_EQ(f.size(), 2u);
  EXPECT_EQ(f[0].kind, FaultKind::Freeze);
  EXPECT_EQ(f[0].camera, std::optional<std::size_t>(0));
  EXPECT_DOUBLE_EQ(f[0].to_s, 2.2);
  EXPECT_EQ(f[1].kind, FaultKind::StampBackwards);
  EXPECT_FALSE(f[1].camera.has_value());
  EXPECT_DOUBLE_EQ(f[1].step_s, 0.02);
  EXPECT_TRUE(readFaultConfig(io::ConfigNode::fromString("a: 1\n", "none.yaml")).empty());
  try {
    readFaultConfig(io::ConfigNode::fromString("faults:\n  - {kind: freeze, from_s: 2.0, to_s: 1.0}\n", "bad.yaml"));
    FAIL() << "a window ending before it starts was accepted";
  } catch (const core::InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("bad.yaml"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("to_s"), std::string::npos) << e.what();
  }
  EXPECT_THROW(readFaultConfig(io::ConfigNode::fromString("faults:\n  - {kind: melt, from_s: 0, to_s: 1}\n", "k.yaml")),
               core::InvalidInput);
}


TEST(FaultPlan, WithoutFaultsItHandsTheSourceBackAndNoInjectionPointFires) {
  TwoCameras inner(5);
  FaultPlan plan;
  EXPECT_EQ(&plan.wrap(inner), &inner);
  EXPECT_NO_THROW(plan.beforeDetect(0, 0.1));
  EXPECT_NO_THROW(plan.beforeCommand(0.1));
  EXPECT_EQ(plan.detected(0, 0.1, Eigen::Vector2d(3.0, 4.0), 640, 480), Eigen::Vector2d(3.0, 4.0));
  EXPECT_TRUE(plan.report().empty());
}

TEST(FaultPlan, DetectionFaultsHitTheirCameraAndWindowAndTheGuardRefusesEveryOne) {
  FaultConfig cfg;
  cfg.faults = {{FaultKind::DetectNan, 0, 0.10, 0.20}, {FaultKind::DetectInf, 1, 0.10, 0.20},
                {FaultKind::DetectOutside, std::nullopt, 0.30, 0.40}};
  FaultPlan plan(cfg, 3);
  const Eigen::Vector2d px(100.0, 200.0);
  int refused = 0;
  for (int i = 0; i < 50; ++i) {  // camera i % 2 at 0.01 i s
    const std::size_t cam = static_cast<std::size_t>(i % 2);
    const Eigen::Vector2d got = plan.detected(cam, 0.01 * i, px, 640, 480);
    if (!usablePixel(got, 640, 480)) ++refused;
    else EXPECT_EQ(got, px);
  }
  const FaultReport r = plan.report();
  EXPECT_EQ(r.of(FaultKind::DetectNan), 5u);      // camera 0 at 0.10, 0.12, ..., 0.18
  EXPECT_EQ(r.of(FaultKind::DetectInf), 5u);      // camera 1 at 0.11, ..., 0.19
  EXPECT_EQ(r.of(FaultKind::DetectOutside), 10u); // both cameras in [0.30, 0.40)
  EXPECT_EQ(refused, 20);
  EXPECT_TRUE(usablePixel(Eigen::Vector2d(-0.5, 479.5), 640, 480));
  EXPECT_FALSE(usablePixel(Eigen::Vector2d(-0.6, 10.0), 640, 480));
}

TEST(FaultPlan, AThrowingDetectorIsCaughtCountedAndTheNextFrameIsDetected) {
  FaultConfig cfg;
  cfg.faults = {{FaultKind::DetectorThrow, 1, 0.0, 0.05}};
  FaultPlan plan(cfg, 1);
  int calls = 0;
  const auto detect = [&] { return ++calls; };
  EXPECT_FALSE(guardedDetect(plan, 1, 0.02, detect).has_value());  // injected: detector never runs
  EXPECT_EQ(guardedDetect(plan, 0, 0.02, detect), std::optional<int>(1));  // the other camera
  EXPECT_EQ(guardedDetect(plan, 1, 0.06, detect), std::optional<int>(2));  // after the window
  const auto own_throw = []() -> int { throw std::runtime_error("detector bug"); };
  EXPECT_FALSE(guardedDetect(plan, 0, 0.5, own_throw).has_value());  // the detector's own exception
  EXPECT_EQ(plan.report().of(FaultKind::DetectorThrow), 1u);
  EXPECT_EQ(plan.report().outcomeOf("detector_errors"), 2u);
  EXPECT_THROW(plan.beforeDetect(1, 0.01), InjectedFault);
}

TEST(FaultPlan, LateFramesMissTheDeadlineOnlyWhenTheDelayExceedsIt) {
  FaultConfig cfg;
  cfg.faults = {{FaultKind::Late, 0, 0.0, 0.1, 0.01, 0.08}, {FaultKind::Late, 1, 0.0, 0.1, 0.01, 0.02}};
  cfg.frame_deadline_s = 0.05;
  FaultPlan plan(cfg, 1);
  TwoCameras inner(10);
  FrameSource& s = plan.wrap(inner);
  EXPECT_EQ(&s, &inner);  // no frame fault: the source itself
  int missed = 0;
  for (const Frame& f : drain(s)) missed += plan.missesDeadline(f);
  EXPECT_EQ(missed, 5);  // camera 0 at 0.00, 0.02, ..., 0.08; camera 1's 20 ms delay is within it
  EXPECT_EQ(plan.report().of(FaultKind::Late), 10u);
}

TEST(FaultPlan, RobotFaultsFailTheCommandsOfTheirWindowWhateverTheCamera) {
  FaultConfig cfg;
  cfg.faults = {{FaultKind::RobotSilent, 0, 0.5, 0.6}, {FaultKind::RobotLimitError, std::nullopt, 0.7, 0.72}};
  FaultPlan plan(cfg, 1);
  int silent = 0, limit = 0, sent = 0;
  for (int i = 0; i < 100; ++i) {
    try {
      plan.beforeCommand(0.01 * i);
      ++sent;
    } catch (const InjectedFault& e) {
      (e.kind() == FaultKind::RobotSilent ? silent : limit)++;
    }
  }
  EXPECT_EQ(silent, 10);
  EXPECT_EQ(limit, 2);
  EXPECT_EQ(sent, 88);
  EXPECT_EQ(plan.report().of(FaultKind::RobotSilent), 10u);
  plan.note("robot_holds", 12);
  const nlohmann::json j = toJson(plan.report());
  EXPECT_EQ(j["injected"]["robot_limit_error"], 2);
  EXPECT_EQ(j["outcome"]["robot_holds"], 12);
  EXPECT_EQ(summaryLine(plan.report()),
            "faults injected: robot_limit_error 2, robot_silent 10; outcome: robot_holds 12");
}

TEST(FaultPlan, FrameKindsGoThroughTheDecoratorAndAreReportedWithTheOthers) {
  FaultConfig cfg;
  cfg.faults = {{FaultKind::Blackout, 1, 0.0, 0.1}, {FaultKind::DetectNan, 0, 0.0, 0.1}};
  FaultPlan plan(cfg, 1);
  TwoCameras inner(10);
  FrameSource& s = plan.wrap(inner);
  EXPECT_NE(&s, &inner);
  int lost = 0;
  drain(s, &lost);
  EXPECT_EQ(lost, 5);
  EXPECT_EQ(plan.report().of(FaultKind::Blackout), 5u);
  EXPECT_EQ(plan.report().of(FaultKind::DetectNan), 0u);  // configured, nothing detected yet
  EXPECT_EQ(plan.report().injected.size(), 2u);
}

TEST(FaultConfig, ReadsTheNewKindsTheDelayAndTheDeadline) {
  const io::ConfigNode root = io::ConfigNode::fromString(
      "faults:\n"
      "  - {kind: late, camera: 1, from_s: 0.5, to_s: 0.7, delay_s: 0.2}\n"
      "  - {kind: robot_limit_error, from_s: 1.0, to_s: 1.1}\n"
      "frame_deadline_s: 0.04\n",
      "plan.yaml");
  const FaultConfig c = readFaultPlanConfig(root);
  ASSERT_EQ(c.faults.size(), 2u);
  EXPECT_EQ(c.faults[0].kind, FaultKind::Late);
  EXPECT_DOUBLE_EQ(c.faults[0].delay_s, 0.2);
  EXPECT_EQ(c.faults[1].kind, FaultKind::RobotLimitError);
  EXPECT_DOUBLE_EQ(c.frame_deadline_s, 0.04);
  EXPECT_THROW(readFaultPlanConfig(io::ConfigNode::fromString(
                   "faults:\n  - {kind: late, from_s: 0, to_s: 1, delay_s: -1}\n", "d.yaml")),
               core::InvalidInput);
  EXPECT_EQ(std::string(toString(FaultKind::RobotLimitError)), "robot_limit_error");
}

TEST(StaleFrameFilter, ARepeatedImageIsStaleABlankOneIsNot) {
  StaleFrameFilter stale;
  Frame f;
  f.image = cv::Mat(4, 4, CV_8UC3);
  cv::randu(f.image, cv::Scalar::all(0), cv::Scalar::all(256));
  EXPECT_FALSE(stale.repeats(f));  // the first image of camera 0
  f.stamp = 0.02;
  EXPECT_TRUE(stale.repeats(f));   // the same pixels again, a new stamp
  f.camera = 1;
  EXPECT_FALSE(stale.repeats(f));  // another camera's own history
  Frame dark;
  dark.image = cv::Mat(4, 4, CV_8UC3, cv::Scalar::all(0));
  EXPECT_FALSE(stale.repeats(dark));
  EXPECT_FALSE(stale.repeats(dark));  // a covered camera: blank, not stale
}

}  // namespace
}  // namespace viewline::runtime
