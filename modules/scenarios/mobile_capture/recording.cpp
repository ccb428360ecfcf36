#include "viewline/scenarios/mobile_capture/recording.h"

#include <filesystem>
#include <utility>
#include <vector>

#include "viewline/core/error.h"
#include "viewline/runtime/faults.h"
#include "viewline/scenarios/mobile_capture/chase.h"

namespace viewline::scenarios {

namespace fs = std::filesystem;

namespace {

// The truth columns of a mobile-capture recording: the object's state at the frame's stamp.
const std::vector<std::string> kTruthColumns = {"x", "y", "theta", "v", "omega"};

std::vector<double> truthOf(const sim::GroundState& s) { return {s.x, s.y, s.theta, s.v, s.omega}; }

// A head.csv row: the reading in headTableColumns()' order, and back.
std::vector<double> headRow(const mobile_capture::HeadReading& r) {
  return {r.base.x, r.base.y, r.base.theta, r.q.tilt, r.q.pan};
}
mobile_capture::HeadReading headReadingOf(const std::vector<double>& v) {
  mobile_capture::HeadReading r;
  r.base = {v[0], v[1], v[2]};
  r.q.tilt = v[3];
  r.q.pan = v[4];
  return r;
}

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

const std::vector<std::string>& headTableColumns() {
  static const std::vector<std::string> c = {"x", "y", "theta", "tilt", "pan"};
  return c;
}

void MobileCaptureFrames::record(const std::string& run_dir, const core::Camera& camera, HeadProvider head) {
  writer_ = std::make_unique<runtime::RecordingWriter>(run_dir);
  writer_->setCamera(0, camera);
  writer_->setTruthColumns(kTruthColumns);
  writer_->setTable(kHeadTable, headTableColumns());  // a replay without the robot needs its readings
  head_ = std::move(head);
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
    // The loop processes the frame at this instant, with this reading (loop.cpp).
    writer_->tableRow(kHeadTable, frame->camera, frame->sequence, headRow(head_()));
  }
  return frame;
}

RecordedMobileCaptureRun mobileCaptureRecordedMeasurements(const MobileCaptureConfig& cfg, const std::string& run_dir,
                                                           std::uint64_t fault_seed) {
  cfg.validate();
  if (!fs::is_regular_file(fs::path(run_dir) / "recording.csv"))
    throw core::InvalidInput(run_dir + ": not a recording (no recording.csv, as each run_iii/ of mobile_capture "
                             "--record DIR holds)");
  RecordedMobileCaptureRun out;
  out.dir = run_dir;
  runtime::RecordingSource source(run_dir);
  if (source.cameraCount() != 1)
    throw core::InvalidInput(run_dir + "/recording.csv: frames of " + std::to_string(source.cameraCount()) +
                             " cameras; the head camera is one");
  const std::string head_file = run_dir + "/" + kHeadTable + ".csv";
  const std::optional<runtime::RecordingTruth> head = source.table(kHeadTable);
  if (!head)
    throw core::InvalidInput(run_dir + ": no " + std::string(kHeadTable) +
                             ".csv (the base pose and head joints per frame, which mobile_capture --record writes): "
                             "without them a detection cannot be placed on the floor");
  if (head->columns != headTableColumns())
    throw core::InvalidInput(head_file + ": unexpected columns (expected camera,sequence,x,y,theta,tilt,pan)");

  // The loop's perception (loop.cpp, process): the same screens, camera, detector and track.
  runtime::FaultPlan faults(cfg.faults, fault_seed);
  runtime::FrameSource& frames = faults.wrap(source);
  mobile_capture::FrameScreen screen;
  mobile_capture::ChaseController chase(cfg);
  const robots::MobilePanTilt head_kinematics(cfg.head);
  core::Camera camera = mobile_capture::estimatorCamera(cfg);
  while (frames.nextReadyTime()) {
    const std::optional<runtime::Frame> frame = frames.grab();
    if (!frame) continue;  // a lost grab: nothing measured, as in the loop
    ++out.frames;
    const auto row = head->rows.find({frame->camera, frame->sequence});
    if (row == head->rows.end())
      throw core::InvalidInput(head_file + ": no row for camera " + std::to_string(frame->camera) + " sequence " +
                               std::to_string(frame->sequence) + " of recording.csv");
    if (!screen.admit(faults, *frame)) continue;
    const mobile_capture::HeadReading reading = headReadingOf(row->second);
    camera.c_M_w = mobile_capture::estimatorCamera_c_M_w(cfg, head_kinematics, reading);
    const mobile_capture::ChaseObservation o = chase.frame(faults, *frame, camera, reading.base);
    if (o.floor) out.measurements.push_back({frame->stamp, frame->sequence, *o.floor});
  }
  return out;
}

}  // namespace viewline::scenarios
