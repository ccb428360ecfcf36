#include "viewline/scenarios/dart/footage.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

#include "viewline/core/error.h"
#include "viewline/core/random.h"
#include "viewline/runtime/faults.h"
#include "viewline/runtime/merged_source.h"
#include "viewline/runtime/stale_frames.h"
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
                     runtime::TelemetrySink* tel, runtime::FaultPlan& faults)
      : cfg_(cfg), cams_(std::move(cams)), tracker_(cams_, cfg.trackerConfig()), sum_(sum), tel_(tel),
        faults_(faults), plane_(dartBoardPlane(cfg)) {
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
    // The detector behind the fault plan's injection point and the loops' defences (as ball
    // catching's detectCatchBall): an exception is counted (detector_errors), not thrown; the
    // detect_* faults act on the centre; a non-finite or outside centre is counted and dropped.
    const auto r = runtime::guardedDetect(faults_, ci, f.stamp, [&] {
      return detectors_[ci].detect(f.image, f.stamp, predicted);
    });
    if (!r || !r->ok()) return;
    vision::BallMeasurement det = r->value();
    det.pixel = faults_.detected(ci, f.stamp, det.pixel, f.image.cols, f.image.rows);
    if (!runtime::usablePixel(det.pixel, f.image.cols, f.image.rows)) {
      faults_.note("detections_rejected");
      return;
    }
    ++sum_.detections;
    ++sum_.cameras[ci].detections;
    // The std told to the tracker: as measured (detector.sigma_px), else the blob's own, floored.
    const double sigma = cfg_.detector_sigma_px > 0.0
                             ? cfg_.detector_sigma_px
                             : std::max(cfg_.detector_sigma_px_floor, std::sqrt(0.5 * det.pixel_covariance.trace()));
    // A pause longer than a track can coast (or than the tracker accepts as a step forward) ends
    // the dart: the tracker starts afresh, as for a new throw (its buffer and counters too, which
    // would refuse a stamp that far ahead).
    if (submitted_ && f.stamp - last_submit_ > std::min(cfg_.tracker.max_coast, cfg_.tracker.max_forward_gap)) {
      tracks_before_ += trackCount();
      tracker_.reset();
    }
    submitted_ = true;
    last_submit_ = std::max(last_submit_, f.stamp);
    const tracking::ImageMeasurement m{next_id_++, ci, f.stamp, det.pixel, sigma};
    if (tel_) tel_->measurement({"camera" + std::to_string(ci), m.t, m.id, m.uv, Eigen::VectorXd::Constant(2, sigma)});
    if (const tracking::Refusal refusal = tracker_.submit(m); refusal != tracking::Refusal::None) {
      faults_.note(std::string("tracker_refused_") + tracking::toString(refusal));
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
  runtime::FaultPlan& faults_;
  planning::CrossingPlane plane_;
  planning::CrossingModel model_;
  std::uint64_t next_id_ = 1;
  bool submitted_ = false;    // an image went to the tracker
  double last_submit_ = 0.0;  // s, the newest stamp submitted
  int tracks_before_ = 0;     // tracks of the tracker before its last reset
  double nis_sum_ = 0.0;
};

}  // namespace

DartFootageSummary runDartFootage(const DartScenarioConfig& cfg, runtime::TelemetrySink* telemetry,
                                  runtime::WallClock* clock, std::uint64_t seed) {
  cfg.validate();
  if (!cfg.onFootage()) throw core::InvalidInput("cameras[].source: no camera has footage (sim: runDartExperiments)");
  const auto wall0 = std::chrono::steady_clock::now();
  DartFootageSummary sum;
  sum.seed = seed;
  std::vector<runtime::MergedCamera> footage;
  for (const DartCameraConfig& c : cfg.cameras) footage.push_back({c.name, c.source, c.width, c.height});
  runtime::MergedFrameSource source(footage, clock);
  for (std::size_t i = 0; i < source.cameraCount(); ++i) sum.cameras.push_back({cfg.cameras[i].name, source.sourceName(i), 0, 0, 0});
  const std::optional<double> first = source.nextReadyTime();
  if (!first) throw core::InvalidInput("cameras[].source: the footage holds no frame");
  sum.t_first = *first;
  sum.t_last = *first;

  // Live: each frame timed from its grab to the end of its processing, against one frame period
  // of the fastest camera (as ball catching's footage session).
  std::optional<runtime::ProcessingTimer> timer;
  double rate = 0.0;
  for (const DartCameraConfig& c : cfg.cameras) rate = std::max(rate, c.rate_hz);
  char origin[96];
  std::snprintf(origin, sizeof origin, "one frame period at %.4g fps (the fastest camera's rate_hz)", rate);
  if (source.live()) timer.emplace(1.0 / rate, clock);

  runtime::FaultPlan faults(cfg.faults, core::deriveSeed(seed, 0xFA));
  runtime::FrameSource& frames = faults.wrap(source);
  runtime::StaleFrameFilter stale;
  DartFootageSession session(cfg, makeDartCameras(cfg), sum, telemetry, faults);
  std::uint64_t frame_count = 0;
  while (const std::optional<double> t = frames.nextReadyTime()) {
    sum.t_last = std::max(sum.t_last, *t);
    const std::optional<runtime::Frame> f = frames.grab();
    if (!f) continue;  // lost (counted by the source)
    const std::uint64_t id = ++frame_count;
    if (timer) timer->resume(id);
    if (faults.missesDeadline(*f)) {
      faults.note("frames_late_dropped");
    } else if (stale.repeats(*f)) {  // a frozen camera's old image with a new stamp (stale_frames.h)
      faults.note("frames_frozen_dropped");
    } else {
      session.frame(*f);
    }
    if (timer) timer->finish(id);
  }
  session.finish();
  for (std::size_t i = 0; i < source.cameraCount(); ++i) {
    sum.cameras[i].frames = source.frames(i);
    sum.cameras[i].lost = source.lost(i);
    sum.frames += source.frames(i);
  }
  if (timer) sum.live = runtime::liveReport(source, *timer, origin);
  // Reported when anything was counted: injected faults, or the defences' own catches (a
  // detector's exception, a screened pixel, a refused image) on clean footage too.
  sum.faults = faults.report();
  if (telemetry) telemetry->flush();
  sum.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  return sum;
}

namespace {

nlohmann::json vec3(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

}  // namespace

nlohmann::json dartFootageSummaryJson(const DartFootageSummary& s, const DartScenarioConfig& cfg) {
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
  nlohmann::json j = footageSessionJson("dart_tracking", s);
  j["tracks"] = tracks;
  j["board_plane_x_m"] = cfg.board_center.x();
  j["nis_mean"] = s.nis_samples > 0 ? nlohmann::json(s.nis_mean) : nlohmann::json(nullptr);
  j["nis_samples"] = s.nis_samples;
  j["rmse_position"] = nullptr;
  j["experiments"] = nullptr;
  j["truth"] = "not scored (the frame source has no truth)";
  j["wall_time_s"] = s.wall_s;
  if (s.live) j["live"] = runtime::toJson(*s.live);
  if (!s.faults.empty()) j["faults"] = runtime::toJson(s.faults);
  return j;
}

std::string dartFootageSummaryText(const DartFootageSummary& s, const DartScenarioConfig& cfg) {
  std::string out = footageSessionText("dart_tracking", s);
  char line[512];
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
  out += footageLiveText(s.live);
  if (!s.faults.empty()) out += "  " + runtime::summaryLine(s.faults) + "\n";
  return out;
}

}  // namespace viewline::scenarios
