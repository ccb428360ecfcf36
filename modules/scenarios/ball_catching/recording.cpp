#include "viewline/scenarios/ball_catching/recording.h"

#include <filesystem>
#include <utility>

#include <nlohmann/json.hpp>

#include "viewline/core/error.h"
#include "viewline/io/files.h"
#include "viewline/scenarios/ball_catching/loop.h"

namespace viewline::scenarios {

namespace fs = std::filesystem;

namespace {

// The truth columns of a ball-catching recording (CatchFrameTruth; object_seen: in the frame's truth).
const std::vector<std::string> kTruthColumns = {"object_seen", "in_front", "in_image", "p_x", "p_y", "p_z"};

nlohmann::json vec3(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

Eigen::Vector3d vec3Of(const nlohmann::json& j, const char* key, const std::string& file) {
  if (!j.contains(key) || !j[key].is_array() || j[key].size() != 3)
    throw core::InvalidInput(file + ": '" + key + "' must be a list of 3 numbers");
  Eigen::Vector3d v;
  for (int i = 0; i < 3; ++i) {
    if (!j[key][static_cast<std::size_t>(i)].is_number()) throw core::InvalidInput(file + ": '" + key + "' must be a list of 3 numbers");
    v[i] = j[key][static_cast<std::size_t>(i)].get<double>();
  }
  return v;
}

double numberOf(const nlohmann::json& j, const char* key, const std::string& file) {
  if (!j.contains(key) || !j[key].is_number()) throw core::InvalidInput(file + ": '" + key + "' must be a number");
  return j[key].get<double>();
}

}  // namespace

std::string catchReplayRoot(const BallCatchingConfig& cfg, const CatchHooks* hooks) {
  if (hooks != nullptr && !hooks->replay_dir.empty()) return hooks->replay_dir;
  return cfg.source.kind == runtime::SourceKind::Recording ? cfg.source.recording : std::string();
}

runtime::SourceConfig readCatchSource(const io::ConfigNode& root) {
  runtime::SourceConfig s = runtime::readSourceConfig(root);
  if (!s.simulated() && s.kind != runtime::SourceKind::Recording)
    throw core::InvalidInput(root.location("source") + ": source.kind " + runtime::toString(s.kind) +
                             " is not supported by ball_catching at the top level (sim or recording); footage is "
                             "given per camera of the rig, in the cameras' order: cameras: [{name: right, source: "
                             "{kind: " + runtime::toString(s.kind) + ", ...}}, ...]");
  return s;
}

std::string catchThrowDir(const std::string& dir, int index) { return runtime::sessionUnitDir(dir, "throw", index); }

void beginCatchRecording(const std::string& dir, std::uint64_t seed, int throws, const std::string& config_text) {
  runtime::beginSessionRecording(dir, {"ball_catching", seed, throws, "throw"}, config_text);
}

int recordedCatchThrows(const std::string& dir) { return runtime::readSessionRecording(dir, "ball_catching").units; }

void checkCatchReplay(const std::string& dir, std::uint64_t seed, int throws) {
  runtime::checkSessionReplay(dir, "ball_catching", seed, throws);
}

ThrowDraw readRecordedThrow(const std::string& throw_dir) {
  const std::string file = (fs::path(throw_dir) / "throw.json").string();
  if (!fs::is_regular_file(file)) throw core::InvalidInput(file + ": missing (the throw's truth of a ball_catching recording)");
  const nlohmann::json j = io::readJsonFile(file);
  ThrowDraw d;
  d.release = vec3Of(j, "release_m", file);
  d.aim = vec3Of(j, "aim_m", file);
  d.launch_velocity = vec3Of(j, "launch_velocity_mps", file);
  d.flight_time = numberOf(j, "flight_time_s", file);
  d.distance = numberOf(j, "distance_m", file);
  if (!(d.release.allFinite() && d.aim.allFinite() && d.launch_velocity.allFinite() && d.flight_time > 0.0))
    throw core::InvalidInput(file + ": expected finite points and velocity and a flight time > 0");
  return d;
}

ThrowFrames::ThrowFrames(std::vector<sim::SimCamera> cameras, core::Rng& rng, const sim::RenderSettings& render,
                         const sim::World& world, double t_end, std::string object)
    : rig_(std::make_unique<RigFrameSource>(std::move(cameras), rng, render, world, t_end)), object_(std::move(object)) {}

ThrowFrames::ThrowFrames(const std::string& throw_dir, std::size_t cameras) {
  if (!fs::is_regular_file(fs::path(throw_dir) / "recording.csv"))
    throw core::InvalidInput(throw_dir + ": no recording.csv (a throw of a ball_catching recording; an interrupted "
                             "recording has none for its last throw)");
  replay_ = std::make_unique<runtime::RecordingSource>(throw_dir);
  if (replay_->truthColumns() != kTruthColumns)
    throw core::InvalidInput(throw_dir + "/truth.csv: expected the ball_catching truth columns (object_seen, in_front, "
                             "in_image, p_x, p_y, p_z)");
  if (replay_->cameraCount() > cameras)
    throw core::InvalidInput(throw_dir + "/recording.csv: frames of " + std::to_string(replay_->cameraCount()) +
                             " cameras, the config uses " + std::to_string(cameras) +
                             " (replay with the config of the recording, its config.yaml)");
}

ThrowFrames::~ThrowFrames() = default;

void ThrowFrames::record(const std::string& throw_dir, const std::vector<core::Camera>& cameras, const ThrowDraw& draw) {
  writer_ = std::make_unique<runtime::RecordingWriter>(throw_dir);
  for (std::size_t k = 0; k < cameras.size(); ++k) writer_->setCamera(k, cameras[k]);
  writer_->setTruthColumns(kTruthColumns);
  // nlohmann writes the shortest text that reads back as the same double: the flight replays bit for bit.
  io::writeJsonFile((fs::path(throw_dir) / "throw.json").string(),
                    {{"release_m", vec3(draw.release)},
                     {"aim_m", vec3(draw.aim)},
                     {"launch_velocity_mps", vec3(draw.launch_velocity)},
                     {"flight_time_s", draw.flight_time},
                     {"distance_m", draw.distance}});
}

void ThrowFrames::finishRecording() {
  if (writer_) writer_->finish();
}

std::size_t ThrowFrames::cameraCount() const { return rig_ ? rig_->cameraCount() : replay_->cameraCount(); }

std::optional<core::Timestamp> ThrowFrames::nextReadyTime() const {
  return rig_ ? rig_->nextReadyTime() : replay_->nextReadyTime();
}

std::optional<runtime::Frame> ThrowFrames::grab() {
  const std::optional<core::Timestamp> ready = nextReadyTime();
  std::optional<runtime::Frame> frame = rig_ ? rig_->grab() : replay_->grab();
  if (!frame) {
    if (writer_ && ready) writer_->lost(*ready);
    return frame;
  }
  if (rig_) {
    const sim::ObjectTruth* o = rig_->lastTruthOf(object_);
    last_seen_ = o != nullptr;
    last_ = CatchFrameTruth{};
    if (o != nullptr) {
      last_.in_front = o->in_front;
      last_.in_image = o->in_image;
      last_.p = o->w_M_o.translation();
    }
  } else {
    const auto v = replay_->truth(frame->camera, frame->sequence);
    if (!v)
      throw core::InvalidInput(replay_->dir() + "/truth.csv: no truth for camera " + std::to_string(frame->camera) +
                               " frame " + std::to_string(frame->sequence));
    last_seen_ = (*v)[0] > 0.5;
    last_.in_front = (*v)[1] > 0.5;
    last_.in_image = (*v)[2] > 0.5;
    last_.p = Eigen::Vector3d((*v)[3], (*v)[4], (*v)[5]);
  }
  if (writer_ && ready) {
    writer_->frame(*ready, *frame);
    writer_->truth(frame->camera, frame->sequence,
                   {last_seen_ ? 1.0 : 0.0, last_.in_front ? 1.0 : 0.0, last_.in_image ? 1.0 : 0.0, last_.p.x(), last_.p.y(),
                    last_.p.z()});
  }
  return frame;
}

}  // namespace viewline::scenarios
