#pragma once
// Ball catching on recorded frames: `--record DIR` writes every throw's frames with their clocks and
// the truth; `--replay DIR` (or `source: {kind: recording, path: DIR}`) runs the same session on
// them, and with the same config and seed it gives the same summary bit for bit.
//
// Layout of DIR (a session recording, runtime/recording.h):
//   session.json        {"scenario": "ball_catching", "seed": S, "units": N, "unit": "throw"}
//   config.yaml         the scenario config as run (after --set edits)
//   throw_iii/          one runtime recording per throw (runtime/recording.h): every camera of the
//                       throw in one index, in grab order (cam<k>/<sequence>.png, camera<k>.xml with
//                       the calibration the estimators use, recording.csv, truth.csv)
//   throw_iii/throw.json  the throw's truth: release and aim points (m, world), launch velocity (m/s,
//                       world), flight time (s) and distance (m), as drawn (ThrowDraw)
// A throw is the unit of a recording as a controller's run is for pan-tilt: each throw has its own
// clock (from 0), cameras and scheduler. The cameras of a throw share one index because the order
// of grabs across cameras is what the tracker saw; a replay in that order reproduces the run.
//
// truth.csv, per frame: object_seen (1 when the tracked object is in the frame's truth), in_front,
// in_image (its centre in front of the camera / inside the image) and p_x, p_y, p_z (its true
// centre at the capture time, m, world; zeros when it is not in the frame: the file holds finite
// numbers only). The loop reads only the visibility; the position is for
// the reader.
//
// What comes from the recording in a replay: the frames, their clocks, lost grabs, the flight
// (throw.json: the tracker's errors, NEES and the catch are scored against it) and the visibility.
// What stays simulated, as live: the robot (the planner drives it from the replayed estimates), and
// the registration before the throws when enabled (it renders its own frames, from the seed).
//
// Footage (images, video, v4l2) is not a recording: it is given per camera (cameras[].source) and
// runs as one session without truth (footage.h); a top-level `source:` of those kinds is refused.

#include <cstdint>
#include <memory>
#include <vector>
#include <optional>
#include <string>
#include <vector>

#include "viewline/core/camera.h"
#include "viewline/runtime/frame_source.h"
#include "viewline/io/config.h"
#include "viewline/runtime/recording.h"
#include "viewline/runtime/source_config.h"
#include "viewline/scenarios/ball_catching/world.h"

namespace viewline::scenarios {

/// The tracked object's truth in one frame (what the loop scores visibility with).
struct CatchFrameTruth {
  bool in_front = false;  ///< the object's centre is in front of the camera (Z > 0)
  bool in_image = false;  ///< its projected centre is inside the image
  Eigen::Vector3d p = Eigen::Vector3d::Zero();  ///< true centre at the capture time, m (world)
};

/// Reads the config's `source:` (runtime::readSourceConfig): sim or recording; other kinds are
/// refused with core::InvalidInput naming file:line and pointing to cameras[].source (footage.h).
runtime::SourceConfig readCatchSource(const io::ConfigNode& root);

/// The folder of throw `index` in a session recording: DIR/throw_iii.
std::string catchThrowDir(const std::string& dir, int index);

/// Starts a session recording: refuses (core::InvalidInput) a folder that exists and is not empty or
/// cannot be created, then writes session.json and config.yaml (when config_text is not empty).
void beginCatchRecording(const std::string& dir, std::uint64_t seed, int throws, const std::string& config_text);

/// The number of throws of a session recording (session.json); throws core::InvalidInput naming the
/// file when DIR holds no ball-catching recording.
int recordedCatchThrows(const std::string& dir);

/// Checks that a session recording can be replayed with this seed and number of throws (the seed
/// also drives the registration and the added pixel noise); throws core::InvalidInput saying what differs.
void checkCatchReplay(const std::string& dir, std::uint64_t seed, int throws);

/// The frames of one throw: the simulator's renderer (optionally recorded) or a recorded throw.
class ThrowFrames : public runtime::FrameSource {
public:
  /// The renderer: sim::CameraRig over `cameras` (rng, render, world, t_end as RigFrameSource);
  /// `object` names the tracked object in the renderer's truth.
  ThrowFrames(std::vector<sim::SimCamera> cameras, core::Rng& rng, const sim::RenderSettings& render,
              const sim::World& world, double t_end, std::string object);
  /// A recorded throw (throw_dir = catchThrowDir(DIR, i)) for a loop with `cameras` cameras; throws
  /// core::InvalidInput naming the file when it is not one (no index, no truth) or holds more cameras.
  ThrowFrames(const std::string& throw_dir, std::size_t cameras);
  ~ThrowFrames() override;
  ThrowFrames(const ThrowFrames&) = delete;
  ThrowFrames& operator=(const ThrowFrames&) = delete;

  /// Records every grab from now on into throw_dir (a new folder): the frames, `cameras` (the
  /// estimators' calibration, ViSP XML) and the throw's truth `draw` (throw.json).
  void record(const std::string& throw_dir, const std::vector<core::Camera>& cameras, const ThrowDraw& draw);
  /// Writes the recording's index (a throw that was not finished leaves no index: it is not replayable).
  void finishRecording();

  std::size_t cameraCount() const override;
  /// The renderer's next end of exposure, or the recorded ready time, s.
  std::optional<core::Timestamp> nextReadyTime() const override;
  /// The next frame (nullopt: lost), recorded when record() was called.
  std::optional<runtime::Frame> grab() override;
  /// The tracked object's truth in the last frame grabbed, or nullptr when it is not in it.
  const CatchFrameTruth* lastTruth() const { return last_seen_ ? &last_ : nullptr; }

private:
  std::unique_ptr<RigFrameSource> rig_;
  std::unique_ptr<runtime::RecordingSource> replay_;
  std::unique_ptr<runtime::RecordingWriter> writer_;
  std::string object_;
  CatchFrameTruth last_;
  bool last_seen_ = false;
};

/// The throw's truth written by a recording (throw.json in throw_dir); throws core::InvalidInput naming the file.
ThrowDraw readRecordedThrow(const std::string& throw_dir);

}  // namespace viewline::scenarios
