#pragma once
// Mobile capture on recorded frames: `--record DIR` writes every run's head-camera frames with their
// clocks, the robot's reading at each frame and the object's truth; `--replay DIR` (or `source:
// {kind: recording, path: DIR}`) runs the same batch on them, and with the same config and seed it
// gives the same summary bit for bit.
//
// Layout of DIR (a session recording, runtime/recording.h):
//   session.json   {"scenario": "mobile_capture", "seed": S, "units": N, "unit": "run"}
//   config.yaml    the scenario config as run (after --set edits)
//   run_iii/       one runtime recording per run (its own clock from 0): cam0/<sequence>.png,
//                  camera0.xml (the estimators' calibration), recording.csv, head.csv, truth.csv
// head.csv, per frame (camera,sequence then headTableColumns(), 17 significant digits): what the
// loop read of the robot when it took the frame, i.e. what turned the frame's detection into the
// track's measurement: x, y (m, world floor) and theta (rad, from the world x axis) of the base
// from odometry, tilt and pan (rad) of the head's encoders (mobile_capture::HeadReading). The
// estimators' camera at that frame is estimatorCamera_c_M_w(cfg, head, reading) (world.h): the DH
// chain of robots::MobilePanTilt at (tilt, pan) on the base pose, with the rig's fixed mount
// correction c'_M_c (mobile_capture.h, "Camera parameters").
// truth.csv, per frame: the object's true state at the frame's stamp, x, y (m, world floor), theta
// (rad), v (m/s), omega (rad/s).
//
// What stays simulated in a replay, from the seed: the object's path (the grasp is scored against
// it at every control tick and the oracle chases it, not only at the frames), the robot (the laws
// drive it from the replayed estimates) and the filter test and field-of-view sweep of the summary.
// The recorded truth is checked against that path at every frame: a recording replayed with another
// seed or object settings is refused (core::InvalidInput naming the frame), never scored against
// the wrong path.
//
// Tuning on a recording (mobileCaptureRecordedMeasurements): without the robot, the simulator, the
// seed or the truth, each recorded frame goes through the loop's own screens and perception
// (mobile_capture::FrameScreen, ChaseController::frame: windowed detection around the track's
// prediction, floorMeasurement) with the estimators' camera placed at the frame's head.csv
// reading. With the config of the recording the measurements are the live run's, bit for bit.
//
// Footage (images, video, v4l2) has no simulated object to grasp or to chase with the oracle: it
// runs as one session with the robot held at its start pose (mobile_capture/footage.h).

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "viewline/core/camera.h"
#include "viewline/io/config.h"
#include "viewline/runtime/frame_source.h"
#include "viewline/runtime/recording.h"
#include "viewline/runtime/source_config.h"
#include "viewline/scenarios/mobile_capture/world.h"
#include "viewline/sim/physics.h"

namespace viewline::scenarios {

/// Reads the config's `source:` (runtime::readSourceConfig): sim or recording (the batch), images,
/// video or v4l2 (one footage session, footage.h); throws core::InvalidInput naming file:line.
runtime::SourceConfig readMobileCaptureSource(const io::ConfigNode& root);

/// Record and replay folders of a batch (runMobileCaptureBatch); empty: none.
struct MobileCaptureSessionIo {
  std::string record_dir;   ///< --record DIR: a new session recording
  std::string replay_dir;   ///< --replay DIR: a session recording to run on (overrides the config's source)
  std::string config_text;  ///< the config as run, written into a recording (config.yaml)
};

/// The session recording a batch replays: io.replay_dir, else the config's `source:` folder, else "" (render).
std::string mobileCaptureReplayRoot(const MobileCaptureConfig& cfg, const MobileCaptureSessionIo& io);
/// The folder of run `index` in a session recording: DIR/run_iii.
std::string mobileCaptureRunDir(const std::string& dir, int index);
/// The number of runs of a session recording; throws core::InvalidInput when DIR holds none.
int recordedMobileCaptureRuns(const std::string& dir);

/// The head camera of one run: the simulator's renderer (optionally recorded) or a recorded run.
class MobileCaptureFrames : public runtime::FrameSource {
public:
  /// The renderer (RenderedHeadCamera: cfg, target, rng, camera_pose as there).
  MobileCaptureFrames(const MobileCaptureConfig& cfg, const sim::GroundTarget& target, mobile_capture::Streams& rng,
                      mobile_capture::RenderedHeadCamera::PoseProvider camera_pose);
  /// A recorded run (run_dir = mobileCaptureRunDir(DIR, i)) whose truth must be `target`'s path;
  /// throws core::InvalidInput naming the file when it is not a mobile-capture run recording.
  MobileCaptureFrames(const std::string& run_dir, const sim::GroundTarget& target);
  ~MobileCaptureFrames() override;
  MobileCaptureFrames(const MobileCaptureFrames&) = delete;
  MobileCaptureFrames& operator=(const MobileCaptureFrames&) = delete;

  /// What the loop reads of the robot at a grab (its base pose and head joints).
  using HeadProvider = std::function<mobile_capture::HeadReading()>;
  /// Records every grab from now on into run_dir (a new folder), with `camera` (the estimators'
  /// calibration, ViSP XML), the robot's reading `head()` at the grab (head.csv) and the object's
  /// truth per frame.
  void record(const std::string& run_dir, const core::Camera& camera, HeadProvider head);
  /// Writes the recording's index (an interrupted run leaves none: it is not replayable).
  void finishRecording();

  std::size_t cameraCount() const override { return 1; }
  /// The renderer's next vision tick, or the recorded ready time, s.
  std::optional<core::Timestamp> nextReadyTime() const override;
  /// The next frame (recorded when record() was called; checked against the truth in a replay).
  std::optional<runtime::Frame> grab() override;

private:
  const sim::GroundTarget& target_;
  std::unique_ptr<mobile_capture::RenderedHeadCamera> renderer_;
  std::unique_ptr<runtime::RecordingSource> replay_;
  std::unique_ptr<runtime::RecordingWriter> writer_;
  HeadProvider head_;
};

/// The per-frame table of a run recording that holds the robot's readings: head.csv.
inline const char* const kHeadTable = "head";
/// Its columns after camera,sequence: x, y, theta (base pose), tilt, pan (head joints); see the
/// header comment.
const std::vector<std::string>& headTableColumns();

/// One detection of a recorded run as the track was given it.
struct RecordedFloorMeasurement {
  double t = 0.0;                             ///< the frame's stamp, s
  std::uint64_t sequence = 0;                 ///< the frame's sequence number
  mobile_capture::FloorMeasurement floor;     ///< the floor point and its noise parts
};

/// A recorded run through the loop's perception (header comment, "Tuning on a recording").
struct RecordedMobileCaptureRun {
  std::string dir;                                     ///< the run's folder
  std::size_t frames = 0;                              ///< frames the recording holds (lost grabs not counted)
  std::vector<RecordedFloorMeasurement> measurements;  ///< in frame order
};

/// The measurements of the run recording in `run_dir` (mobileCaptureRunDir(DIR, i)) through the
/// screens, detector and geometry of `cfg` (its faults seeded with `fault_seed`, as a footage
/// session's). Truth is not read. Throws core::InvalidInput naming the folder or file: no
/// recording.csv, not one camera, no head.csv (or other columns), a frame without its head.csv row.
RecordedMobileCaptureRun mobileCaptureRecordedMeasurements(const MobileCaptureConfig& cfg, const std::string& run_dir,
                                                           std::uint64_t fault_seed);

}  // namespace viewline::scenarios
