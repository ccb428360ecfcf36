#include "viewline/scenarios/mobile_capture/recording.h"

#include <filesystem>
#include <utility>
#include <vector>

#include "viewline/core/error.h"

namespace viewline::scenarios {

namespace fs = std::filesystem;

namespace {

// The truth columns of a mobile-capture recording: the object's state at the frame's stamp.
const std::vector<std::string> kTruthColumns = {"x", "y", "theta", "v", "omega"};

std::vector<double> truthOf(const sim::GroundState& s) { return {s.x, s.y, s.theta, s.v, s.omega}; }

}  // namespace

runtime::SourceConfig readMobileCaptureSource(const io::ConfigNode& root) {
  // Every kind: sim and recording run the batch (recording.h), footage one session (footage.h).
  return runtime::readSourceConfig(root);
}

std::string mobileCaptureReplayRoot(const MobileCaptureConfig& cfg, const MobileCaptureSessionIo& io) {
  if (!io.replay_dir.empty()) return io.replay_dir;
  return cfg.source.kind == runtime::SourceKind::Recording ? cfg.source.recording : std::string();
}

std::string mobileCaptureRunDir(const std::string& dir, int index) { return runtime::sessionUnitDir(dir, "run", index); }

int recordedMobileCaptureRuns(const std::string& dir) { return runtime::readSessionRecording(dir, "mobile_capture").units; }

MobileCaptureFrames::MobileCaptureFrames(const MobileCaptureConfig& cfg, const sim::GroundTarget& target,
                                         mobile_capture::Streams& rng,
                                         mobile_capture::RenderedHeadCamera::PoseProvider camera_pose)
    : target_(target),
      renderer_(std::make_unique<mobile_capture::RenderedHeadCamera>(cfg, target, rng, std::move(camera_pose))) {}

MobileCaptureFrames::MobileCaptureFrames(const std::string& run_dir, const sim::GroundTarget& target) : target_(target) {
  if (!fs::is_regular_file(fs::path(run_dir) / "recording.csv"))
    throw core::InvalidInput(run_dir + ": no recording.csv (a run of a mobile_capture recording; an interrupted "
                             "recording has none for the runs it did not finish)");
  replay_ = std::make_unique<runtime::RecordingSource>(run_dir);
  if (replay_->truthColumns() != kTruthColumns)
    throw core::InvalidInput(run_dir + "/truth.csv: expected the mobile_capture truth columns (x, y, theta, v, omega)");
  if (replay_->cameraCount() != 1)
    throw core::InvalidInput(run_dir + "/recording.csv: frames of " + std::to_string(replay_->cameraCount()) +
                             " cameras; the head camera is one");
}

MobileCaptureFrames::~MobileCaptureFrames() = default;

void MobileCaptureFrames::record(const std::string& run_dir, const core::Camera& camera) {
  writer_ = std::make_unique<runtime::RecordingWriter>(run_dir);
  writer_->setCamera(0, camera);
  writer_->setTruthColumns(kTruthColumns);
}

void MobileCaptureFrames::finishRecording() {
  if (writer_) writer_->finish();
}

std::optional<core::Timestamp> MobileCaptureFrames::nextReadyTime() const {
  return renderer_ ? renderer_->nextReadyTime() : replay_->nextReadyTime();
}

std::optional<runtime::Frame> MobileCaptureFrames::grab() {
  const std::optional<core::Timestamp> ready = nextReadyTime();
  std::optional<runtime::Frame> frame = renderer_ ? renderer_->grab() : replay_->grab();
  if (!frame) {
    if (writer_ && ready) writer_->lost(*ready);
    return frame;
  }
  const std::vector<double> truth = truthOf(target_.state(frame->stamp));
  if (replay_) {
    const auto recorded = replay_->truth(frame->camera, frame->sequence);
    if (!recorded || *recorded != truth)
      throw core::InvalidInput(replay_->dir() + "/truth.csv: frame " + std::to_string(frame->sequence) +
                               (recorded ? ": the recorded object is not on the path this seed and config simulate"
                                         : ": no truth") +
                               " (replay with the config and --seed of the recording)");
  }
  if (writer_ && ready) {
    writer_->frame(*ready, *frame);
    writer_->truth(frame->camera, frame->sequence, truth);
  }
  return frame;
}

}  // namespace viewline::scenarios
