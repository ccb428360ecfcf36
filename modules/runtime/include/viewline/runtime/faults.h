#pragma once
// Injected camera faults: a FrameSource decorator that makes any source (the renderer, a video, a
// recording) misbehave the way real cameras and drivers do, over windows of capture time, and
// counts what it did, so that a scenario run can show what its tracker and controller make of it.
//
//   faults:                                   # a scenario config's list (readFaultConfig)
//     - {kind: freeze, camera: 0, from_s: 2.0, to_s: 2.2}          # same image, new stamps
//     - {kind: stamp_repeat, camera: 1, from_s: 3.0, to_s: 3.1}     # the previous frame's stamp again
//     - {kind: stamp_backwards, from_s: 4.0, to_s: 4.05, step_s: 0.01}  # stamp before the previous one
//     - {kind: blackout, camera: 0, from_s: 5.0, to_s: 6.0}         # no frames: the camera stops, comes back
//     - {kind: corrupt, camera: 1, from_s: 7.0, to_s: 7.1}          # garbage pixels (uniform noise)
//     - {kind: detect_nan, camera: 0, from_s: 1.0, to_s: 1.1}       # the detector reports a NaN centre
//     - {kind: detect_inf, from_s: 1.0, to_s: 1.1}                  # ... an infinite centre
//     - {kind: detect_outside, from_s: 1.0, to_s: 1.1}              # ... a centre outside the image
//     - {kind: detector_throw, camera: 1, from_s: 1.0, to_s: 1.2}   # the detector throws
//     - {kind: late, camera: 0, from_s: 1.0, to_s: 1.2, delay_s: 0.1}  # delivered 0.1 s late
//     - {kind: robot_silent, from_s: 0.5, to_s: 0.6}                # the robot stops answering
//     - {kind: robot_limit_error, from_s: 0.5, to_s: 0.52}          # the robot refuses: limit error
//   frame_deadline_s: 0.05                    # a frame delivered later than this after capture is dropped
//
// A fault applies to the frames whose capture time lies in [from_s, to_s) of the given camera
// (every camera when `camera` is absent). A frozen frame repeats the last good image of its
// camera (a driver handing out a stale buffer); the stamps are the source's own unless a stamp
// fault is active too. Blacked-out frames are lost (grab() returns nothing, as a source does for
// a dropped frame). Corrupt images are seeded uniform noise, so runs stay reproducible.
//
// The other kinds act where a loop calls FaultPlan's injection points: on a detector's output
// (detect_*: the frame's camera and capture time), in the detector (detector_throw), on the
// delivery of a frame (late), on a robot command (robot_*: the command's time, any camera). The
// loop's defences are real code that runs with or without injected faults: usablePixel() screens
// every detection, a detector exception is caught, a frame past its deadline is dropped, a
// failed robot command is not taken as sent. FaultPlan counts what was injected and what the
// loop did about it (FaultReport: the summary's `faults` object).

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "viewline/core/error.h"
#include "viewline/core/random.h"
#include "viewline/io/config.h"
#include "viewline/io/config_reference.h"
#include "viewline/runtime/frame_source.h"

namespace viewline::runtime {

/// What an injected fault does to a frame.
enum class FaultKind {
  Freeze,          ///< the camera's last good image again, with a new stamp
  StampRepeat,     ///< the stamp of the camera's previous frame again
  StampBackwards,  ///< a stamp step_s before the camera's previous frame's
  Blackout,        ///< the frame is lost (the camera stops, and comes back after the window)
  Corrupt,         ///< the image replaced by uniform noise
  DetectNan,       ///< the detector's centre becomes NaN
  DetectInf,       ///< the detector's centre becomes +Inf
  DetectOutside,   ///< the detector's centre lands outside the image
  DetectorThrow,   ///< the detector throws (InjectedFault)
  Late,            ///< the frame is delivered delay_s after it is ready
  RobotSilent,     ///< the robot stops answering: commands fail (InjectedFault), none reaches it
  RobotLimitError, ///< the robot refuses commands with a limit error (InjectedFault)
};
/// Number of fault kinds (the size of FaultCounters::frames).
inline constexpr std::size_t kFaultKinds = 12;

/// The kind's config name: "freeze", "stamp_repeat", ..., "robot_limit_error".
const char* toString(FaultKind kind);

/// One injected fault: what, on which camera, over which window of capture time.
struct FaultSpec {
  FaultKind kind = FaultKind::Freeze;  ///< what it does
  std::optional<std::size_t> camera;   ///< the camera it hits (none: every camera)
  core::Timestamp from_s = 0.0;        ///< start of the window (capture time), s
  core::Timestamp to_s = 0.0;          ///< end of the window (excluded), s
  double step_s = 0.01;                ///< StampBackwards: how far before the previous stamp, s
  double delay_s = 0.1;                ///< Late: delivery after the frame is ready, s
};

/// A scenario's `faults:` list and the loop's frame deadline.
struct FaultConfig {
  std::vector<FaultSpec> faults;  ///< the injected faults (empty: none)
  /// A frame delivered more than this after its ready time is dropped, s (late faults only).
  double frame_deadline_s = 0.05;
};

/// A fault thrown at an injection point (detector, robot command): the loop must catch it and go on.
class InjectedFault : public core::Error {
public:
  /// The fault of `kind`, with a message saying where.
  InjectedFault(FaultKind kind, const std::string& what) : core::Error(what), kind_(kind) {}
  /// What was injected.
  FaultKind kind() const { return kind_; }

private:
  FaultKind kind_;
};

/// What the decorator did, per fault kind (indexed by FaultKind).
struct FaultCounters {
  std::array<std::uint64_t, kFaultKinds> frames{};  ///< frames each kind changed (or dropped)
  /// Frames changed or dropped by kind k.
  std::uint64_t of(FaultKind k) const { return frames[static_cast<std::size_t>(k)]; }
  /// Frames any fault touched (a frame hit by two faults counts once).
  std::uint64_t touched = 0;
};

/// A FrameSource that passes another one's frames through the faults (header comment).
class FaultInjectingSource : public FrameSource {
public:
  /// Wraps `inner` (not owned; it must outlive this object). Throws core::InvalidInput on a
  /// window with to_s <= from_s, a negative or non-finite time, a step_s <= 0 or a camera index
  /// the source does not have.
  FaultInjectingSource(FrameSource& inner, std::vector<FaultSpec> faults, std::uint64_t seed);
  /// The inner source's camera count.
  std::size_t cameraCount() const override { return inner_.cameraCount(); }
  /// The inner source's next ready time (faults do not move frames in time).
  std::optional<core::Timestamp> nextReadyTime() const override { return inner_.nextReadyTime(); }
  /// The inner source's next frame, with the faults active at its capture time applied.
  std::optional<Frame> grab() override;
  /// What the faults did so far.
  const FaultCounters& counters() const { return counters_; }
  /// The faults, as given.
  const std::vector<FaultSpec>& faults() const { return faults_; }

private:
  struct CameraMemory {
    cv::Mat last_good;                       // the last image no fault touched
    std::optional<core::Timestamp> last_stamp;  // the stamp of the last frame handed out
  };
  FrameSource& inner_;
  std::vector<FaultSpec> faults_;
  core::Rng rng_;
  std::vector<CameraMemory> memory_;
  FaultCounters counters_;
  bool freezes_ = false;  // some fault freezes: keep each camera's last good image
};

/// Reads the `faults:` list of a scenario config (absent: none); throws core::InvalidInput
/// naming file:line and key on a bad kind, window or value. Camera indices are checked against
/// the source when the decorator is built.
std::vector<FaultSpec> readFaultConfig(const io::ConfigNode& root);

/// Reads the `faults:` list and `frame_deadline_s` (read only when the list has a late fault).
FaultConfig readFaultPlanConfig(const io::ConfigNode& root);

/// The key table of the `faults:` list and `frame_deadline_s` (for a scenario's config_keys.cpp).
std::vector<io::ConfigKeyDoc> faultConfigKeys();

/// A config snippet that reads every fault key (a scenario's config-reference probe).
std::string faultConfigProbe();

/// The guard a loop applies to every detected pixel: finite, and its centre inside the image
/// (u in [-0.5, width - 0.5], v in [-0.5, height - 0.5], pixel centres at integers), px.
bool usablePixel(const Eigen::Vector2d& px, int width, int height);

/// What was injected (per kind, the frames, detections or commands it hit) and what the loop
/// did about it (outcome counters, named by the loop: "detections_rejected", "robot_holds", ...).
struct FaultReport {
  std::map<std::string, std::uint64_t> injected;  ///< per configured kind (toString names)
  std::map<std::string, std::uint64_t> outcome;   ///< per outcome the loop counted
  /// Adds another run's counters (the throws of a session, the runs of a comparison).
  void add(const FaultReport& other);
  /// No fault configured and nothing counted.
  bool empty() const { return injected.empty() && outcome.empty(); }
  /// The count of one kind (0 when absent).
  std::uint64_t of(FaultKind kind) const;
  /// One outcome counter (0 when absent).
  std::uint64_t outcomeOf(const std::string& name) const;
};

/// The summary's `faults` object: {"injected": {kind: n}, "outcome": {name: n}}.
nlohmann::json toJson(const FaultReport& r);

/// One console line: "faults injected: freeze 10, late 2; outcome: frames_late_dropped 2".
std::string summaryLine(const FaultReport& r);

/// A scenario loop's faults: the source decorator for the frame kinds, the injection points for
/// the others, and the counters (header comment). Built empty (no faults) it changes nothing:
/// wrap() hands the inner source back and no injection point ever fires.
class FaultPlan {
public:
  /// No faults.
  FaultPlan() = default;
  /// The faults of `config`, seeded (corrupt images); throws core::InvalidInput as
  /// FaultInjectingSource does on a bad window.
  FaultPlan(FaultConfig config, std::uint64_t seed);
  /// True when no fault is configured.
  bool empty() const { return cfg_.faults.empty(); }
  /// The source to grab from: `inner` itself when no frame fault is configured, else a
  /// FaultInjectingSource over it (owned by the plan; `inner` must outlive it). Call once.
  FrameSource& wrap(FrameSource& inner);
  /// The detector's injection point: throws InjectedFault when a detector_throw fault is active
  /// for this camera and capture time (s).
  void beforeDetect(std::size_t camera, core::Timestamp capture_time);
  /// A detector's pixel with the detect_* faults active for this camera and capture time (s)
  /// applied (counted); unchanged otherwise, px.
  Eigen::Vector2d detected(std::size_t camera, core::Timestamp capture_time, const Eigen::Vector2d& px, int width,
                           int height);
  /// True when a late fault delays this frame beyond the frame deadline (counted as injected;
  /// the loop drops the frame and counts "frames_late_dropped"). A delay within the deadline is
  /// counted as injected and the frame is used.
  bool missesDeadline(const Frame& frame);
  /// The robot's injection point: throws InjectedFault when a robot_* fault is active at the
  /// command time t (s).
  void beforeCommand(core::Timestamp t);
  /// Counts one outcome of the loop (n times).
  void note(const std::string& outcome, std::uint64_t n = 1);
  /// The counters so far (the decorator's frame counts included).
  FaultReport report() const;
  /// The configuration (faults and deadline).
  const FaultConfig& config() const { return cfg_; }

private:
  const FaultSpec* activeOf(FaultKind kind, std::optional<std::size_t> camera, core::Timestamp t) const;
  void count(FaultKind kind) { ++counts_[static_cast<std::size_t>(kind)]; }
  FaultConfig cfg_;
  std::uint64_t seed_ = 0;
  std::unique_ptr<FaultInjectingSource> source_;
  std::array<std::uint64_t, kFaultKinds> counts_{};  // the non-frame kinds (the decorator counts its own)
  std::map<std::string, std::uint64_t> outcome_;
};

/// Runs `detect()` behind the detector's injection point and the loop's defence: an exception
/// from the detector (injected or its own std::exception) is caught and counted as
/// "detector_errors", and the frame goes on without a detection (nullopt).
template <class Detect>
auto guardedDetect(FaultPlan& plan, std::size_t camera, core::Timestamp capture_time, Detect&& detect)
    -> std::optional<decltype(detect())> {
  try {
    plan.beforeDetect(camera, capture_time);
    return detect();
  } catch (const std::exception&) {
    plan.note("detector_errors");
    return std::nullopt;
  }
}

}  // namespace viewline::runtime
