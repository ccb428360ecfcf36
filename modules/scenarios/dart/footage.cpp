#include "viewline/scenarios/dart/footage.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

#include "viewline/core/error.h"
#include "viewline/runtime/faults.h"
#include "viewline/runtime/merged_source.h"
#include "viewline/scenarios/dart/loop.h"
#include "viewline/scenarios/dart/world.h"
#include "viewline/tracking/tracker.h"
#include "viewline/vision/ball_detector.h"

namespace viewline::scenarios {

planning::CrossingPlane dartBoardPlane(const DartScenarioConfig& cfg) {
  planning::CrossingPlane plane;
  plane.point = cfg.board_center;
  plane.normal = -Eigen::Vector3d::UnitX();  // towards the thrower: the dart comes from -x
  return plane;
}

namespace {

// The session: the tracker, the detectors and the summary, one frame at a time.
class DartFootageSession {
public:
  DartFootageSession(const DartScenarioConfig& cfg, std::vector<core::Camera> cams, DartFootageSummary& sum,
                     runtime::TelemetrySink* tel)
      : cfg_(cfg), cams_(std::move(cams)), tracker_(cams_, cfg.trackerConfig()), sum_(sum), tel_(tel),
        plane_(dartBoardPlane(cfg)) {
    for (const core::Camera& c : cams_) detectors_.emplace_back(cfg.detector, c);
    // The board hit is predicted with the tracker's own model: ballistic, its gravity and
    // process noise (no drag: the tracker has none).
    model_.kind = planning::FlightModel::Ballistic;
    model_.gravity_w = cfg.gravity_w;
    model_.accel_psd = cfg.tracker.model.accel_psd;
  }

  void frame(const runtime::Frame& f) {
    const std::size_t ci = f.camera;
    std::optional<Eigen::Vector2d> predicted;
    // A track that has coasted longer than max_coast_s is over: a window where it would be now
    // only biases the search for the next dart.
    if (tracker_.initialised() && f.stamp - tracker_.state().t() <= cfg_.tracker.max_coast) {
      const double tp = std::max(f.stamp, tracker_.state().t());
      if (auto uv = cams_[ci].project(tracker_.predictAt(tp).x().head<3>())) predicted = *uv;
    }
    std::optional<vision::BallMeasurement> det;
    if (auto r = detectors_[ci].detect(f.image, f.stamp, predicted); r.ok()) det = r.value();
    if (!det || !runtime::usablePixel(det->pixel, f.image.cols, f.image.rows)) return;
    ++sum_.detections;
    ++sum_.cameras[ci].detections;
    // The std told to the tracker: as measured (detector.sigma_px), else the blob's own, floored.
    const double sigma = cfg_.detector_sigma_px > 0.0
                             ? cfg_.detector_sigma_px
                             : std::max(cfg_.detector_sigma_px_floor, std::sqrt(0.5 * det->pixel_covariance.trace()));
    // A pause longer than a track can coast (or than the tracker accepts as a step forward) ends
    // the dart: the tracker starts afresh, as for a new throw (its buffer and counters too, which
    // would refuse a stamp that far ahead).
    if (submitted_ && f.stamp - last_submit_ > std::min(cfg_.tracker.max_coast, cfg_.tracker.max_forward_gap)) {
      tracks_before_ += trackCount();
      tracker_.reset();
    }
    submitted_ = true;
    last_submit_ = std::max(last_submit_, f.stamp);
    const tracking::ImageMeasurement m{next_id_++, ci, f.stamp, det->pixel, sigma};
    if (tel_) tel_->measurement({"camera" + std::to_string(ci), m.t, m.id, m.uv, Eigen::VectorXd::Constant(2, sigma)});
    if (tracker_.submit(m) != tracking::Refusal::None) {
      ++sum_.refused;
      return;
    }
    const auto o = tracker_.outcome(m.id);
    const bool fused = o && o->fate == tracking::Fate::Fused;
    if (tel_ && tracker_.lastUpdate()) tel_->innovation(innovationRecord(*tracker_.lastUpdate(), "dart"));
    if (!fused) {
      ++sum_.gated;
      return;
    }
    ++sum_.fused;
    const int number = tracks_before_ + trackCount();
    if (sum_.tracks.empty() || sum_.tracks.back().track != number) {
      DartFootageTrack& t = sum_.tracks.emplace_back();
      t.track = number;
      t.t_first = f.stamp;
    }
    DartFootageTrack& t = sum_.tracks.back();
    t.t_last = std::max(t.t_last, f.stamp);
    ++t.fused;
    if (tel_) tel_->estimate({"dart", tracker_.state().t(), tracker_.state().x(), tracker_.state().P()});
    // Once the predicted hit time has passed, the dart is in the board: the images after it show a
    // dart at rest (which the ballistic model does not describe), so the prediction stands and
    // those images count in neither the hit nor the NIS.
    if (t.board_hit && f.stamp >= t.board_hit->t) return;
    // NIS of the images tested against their track and fused (a seed is untested, a rejected
    // image is an outlier the gate kept out): the track's consistency on the footage.
    if (const auto& u = tracker_.lastUpdate(); u && u->decision == tracking::GateDecision::Accept) {
      nis_sum_ += u->nis;
      ++sum_.nis_samples;
    }
    // Only a confirmed (trusted) track predicts the board hit; the last such prediction stands.
    if (tracker_.confirmed())
      if (auto c = planning::predictCrossing(tracker_.state(), plane_, model_)) t.board_hit = *c;
  }

  void finish() {
    sum_.tracks_started = tracks_before_ + trackCount();
    sum_.nis_mean = sum_.nis_samples > 0 ? nis_sum_ / static_cast<double>(sum_.nis_samples) : 0.0;
  }

private:
  // Tracks of the tracker since its last reset (a restart after rejections continues the track).
  int trackCount() const { return tracker_.trackState().tracks_started - tracker_.trackState().restarts; }

  const DartScenarioConfig& cfg_;
  std::vector<core::Camera> cams_;
  tracking::ViewlineTracker tracker_;
  std::vector<vision::BallDetector> detectors_;
  DartFootageSummary& sum_;
  runtime::TelemetrySink* tel_;
  planning::CrossingPlane plane_;
  planning::CrossingModel model_;
  std::uint64_t next_id_ = 1;
  bool submitted_ = false;    // an image went to the tracker
  double last_submit_ = 0.0;  // s, the newest stamp submitted
  int tracks_before_ = 0;     // tracks of the tracker before its last reset
  double nis_sum_ = 0.0;
};

}  // namespace

DartFootageSummary runDartFootage(const DartScenarioConfig& cfg, runtime::TelemetrySink* telemetry) {
  cfg.validate();
  if (!cfg.onFootage()) throw core::InvalidInput("cameras[].source: no camera has footage (sim: runDartExperiments)");
  const auto wall0 = std::chrono::steady_clock::now();
  DartFootageSummary sum;
  std::vector<runtime::MergedCamera> footage;
  for (const DartCameraConfig& c : cfg.cameras) footage.push_back({c.name, c.source, c.width, c.height});
  runtime::MergedFrameSource source(footage);
  for (std::size_t i = 0; i < source.cameraCount(); ++i) sum.cameras.push_back({cfg.cameras[i].name, source.sourceName(i), 0, 0, 0});
  const std::optional<double> first = source.nextReadyTime();
  if (!first) throw core::InvalidInput("cameras[].source: the footage holds no frame");
  sum.t_first = *first;
  sum.t_last = *first;
  DartFootageSession session(cfg, makeDartCameras(cfg), sum, telemetry);
  while (const std::optional<double> t = source.nextReadyTime()) {
    sum.t_last = std::max(sum.t_last, *t);
    if (const std::optional<runtime::Frame> f = source.grab()) session.frame(*f);
  }
  session.finish();
  for (std::size_t i = 0; i < source.cameraCount(); ++i) {
    sum.cameras[i].frames = source.frames(i);
    sum.cameras[i].lost = source.lost(i);
    sum.frames += source.frames(i);
  }
  if (telemetry) telemetry->flush();
  sum.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  return sum;
}

namespace {

nlohmann::json vec3(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

}  // namespace

nlohmann::json dartFootageSummaryJson(const DartFootageSummary& s, const DartScenarioConfig& cfg) {
  nlohmann::json cams = nlohmann::json::array();
  for (const auto& c : s.cameras)
    cams.push_back({{"name", c.name}, {"source", c.source}, {"frames", c.frames}, {"lost", c.lost},
                    {"detections", c.detections}});
  nlohmann::json tracks = nlohmann::json::array();
  for (const auto& t : s.tracks) {
    nlohmann::json hit = nullptr;
    if (t.board_hit)
      hit = {{"t_s", t.board_hit->t},
             {"point_m", vec3(t.board_hit->p)},
             {"std_m", t.board_hit->sigmaMax()},
             {"std_t_s", std::sqrt(std::max(0.0, t.board_hit->var_t))}};
    tracks.push_back({{"track", t.track}, {"t_first_s", t.t_first}, {"t_last_s", t.t_last}, {"fused", t.fused},
                      {"board_hit", hit}});
  }
  return {{"scenario", "dart_tracking"},
          {"mode", "footage"},
          {"cameras", cams},
          {"footage_s", {{"first_stamp", s.t_first}, {"last_stamp", s.t_last}}},
          {"frames", s.frames},
          {"detections", s.detections},
          {"fused", s.fused},
          {"gated", s.gated},
          {"refused", s.refused},
          {"tracks_started", s.tracks_started},
          {"tracks", tracks},
          {"board_plane_x_m", cfg.board_center.x()},
          {"nis_mean", s.nis_samples > 0 ? nlohmann::json(s.nis_mean) : nlohmann::json(nullptr)},
          {"nis_samples", s.nis_samples},
          {"rmse_position", nullptr},
          {"experiments", nullptr},
          {"truth", "not scored (the frame source has no truth)"},
          {"wall_time_s", s.wall_s}};
}

std::string dartFootageSummaryText(const DartFootageSummary& s, const DartScenarioConfig& cfg) {
  std::string out;
  char line[512];
  std::snprintf(line, sizeof line,
                "dart_tracking on footage: one session, stamps %.3f to %.3f s, %llu frames, %llu detections\n",
                s.t_first, s.t_last, static_cast<unsigned long long>(s.frames),
                static_cast<unsigned long long>(s.detections));
  out += line;
  for (const auto& c : s.cameras) {
    std::snprintf(line, sizeof line, "  camera %-8s %s: %llu frames, %llu lost, %llu detections\n", c.name.c_str(),
                  c.source.c_str(), static_cast<unsigned long long>(c.frames), static_cast<unsigned long long>(c.lost),
                  static_cast<unsigned long long>(c.detections));
    out += line;
  }
  std::snprintf(line, sizeof line, "  tracker: %d tracks started, %llu images fused, %llu gated, %llu refused\n",
                s.tracks_started, static_cast<unsigned long long>(s.fused), static_cast<unsigned long long>(s.gated),
                static_cast<unsigned long long>(s.refused));
  out += line;
  for (const auto& t : s.tracks) {
    std::snprintf(line, sizeof line, "  track %d (%.3f-%.3f s, %d fused): ", t.track, t.t_first, t.t_last, t.fused);
    out += line;
    if (t.board_hit) {
      std::snprintf(line, sizeof line, "board hit (x = %.3f m) at y %.3f, z %.3f m, t %.3f s, std %.1f mm\n",
                    cfg.board_center.x(), t.board_hit->p.y(), t.board_hit->p.z(), t.board_hit->t,
                    1e3 * t.board_hit->sigmaMax());
      out += line;
    } else {
      out += "no board hit predicted (no confirmed estimate crossing the board plane)\n";
    }
  }
  if (s.nis_samples > 0) {
    std::snprintf(line, sizeof line, "  NIS mean %.2f over %llu tested fused images (2 dof: 2 when consistent)\n",
                  s.nis_mean, static_cast<unsigned long long>(s.nis_samples));
    out += line;
  }
  out += "  RMSE, NEES and the experiments A-E: not scored: no truth (footage has no true flight)\n";
  return out;
}

}  // namespace viewline::scenarios
