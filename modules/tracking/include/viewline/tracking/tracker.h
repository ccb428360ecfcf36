#pragma once
// Multi-view asynchronous viewline tracker ([L], SPEC §2).
//
//   std::vector<core::Camera> cams = ...;            // calibrated rig
//   tracking::TrackerConfig cfg;                     // prior, model, gate, timing
//   tracking::ViewlineTracker tracker(cams, cfg);
//   auto r = tracker.submit({id, camera_index, capture_time, pixel, sigma_px});
//   if (r != tracking::Refusal::None) ++refused[r]; // reason the caller can count
//   tracker.state();                                 // x = (p, ṗ), P at the newest capture time
//   tracker.predictAt(t);                            // e.g. for an interception planner
//
// Every measurement carries its own capture time. Two ways to use it:
//  - TimeMode::Exact: the state is propagated exactly (ballistic.h) to every
//    capture time and the image's two viewline rows are fused there;
//  - TimeMode::DtOffset: the filter runs on a fixed grid of period T; an image
//    captured Δt after the grid instant uses the Δt-offset rows of [L] eq 26.
// Images are fused one at a time (R is block diagonal over images, so this
// equals the stacked update and costs O(#images), not O(#rows³)); each image
// is gated on its own, so one bad camera does not veto the others.
//
// Late data. Processed measurements stay in a buffer for `late_horizon`
// seconds, each with a snapshot of the track state before it. A measurement
// older than the newest one but within the horizon is inserted in capture-time
// order and everything after it is re-processed from the snapshot: the result
// equals in-order processing exactly (same operations in the same order). The
// processing order is (t, camera, id).
//
// Refused (counted by reason, never fused): non-finite stamp or pixel, unknown
// camera, pixel outside the image (+ margin), bad sigma, duplicate (same camera
// and stamp, or same id, within the buffer), older than newest − horizon
// (backwards beyond the horizon), or further than max_forward_gap in the future.
//
// Track start and loss (the life cycle of tracking::TrackGate, one rejection count per camera).
// The first measurement (and any after a gap of max_coast without a fused image) starts a track
// from the configured prior at its capture time and is fused without gating (nothing to gate
// against). After `restart_after_rejections` consecutive gated images of one camera (counted per
// camera: a track seeded by an outlier of camera A can keep agreeing with A while B disagrees)
// the track is judged to have been seeded by a bad measurement: its seed (oldest measurement of
// the track history) is dropped and a new track is started from the prior and re-fed with the
// rest of the history and the current image (gated as usual). A camera's run is outvoted, and
// does not restart the track, when images of at least two other cameras were fused during it
// (TrackGateConfig::outvoted_by): two agreeing views triangulate the track, so the camera that
// disagrees is the biased one (e.g. an unregistered camera of a four-camera rig); with one or two
// cameras this never happens. The state therefore depends only
// on past measurements (causal), which keeps the late-data replay exact.
//
// Robust start (TrackerConfig::start, off by default; track_start.cpp). With confirm_images > 0 a
// new track is TENTATIVE: it keeps its newest images and, after each, searches the largest subset
// of them that one ballistic flight explains (joint chi-square test, up to max_outliers images set
// aside); it is confirmed (confirmed() true: trusted, reported) once that subset is unique and has
// confirm_images images. A restart makes the track tentative again over its newest images, so
// neither a start nor a restart can be seeded by one outlier.
//
// Pixel bias (TrackerConfig::pixel_bias, off by default). A detection's error is not all white:
// the detector's own error (blur, the colour threshold on the ball's shaded side) and the
// calibration / registration error persist along a track and change slowly across the image,
// and a white σ cannot make both NIS and NEES consistent (the filter averages errors that do
// not average out). With sigma_px > 0 each camera c gets a 2-D pixel bias b_c, a first-order
// Gauss-Markov process per axis (exponentially correlated noise, ḃ = −b/τ + w, stationary
// variance σ_b²: Grewal & Andrews, Kalman Filtering: Theory and Practice, the chapter on random
// processes):
//   predict  b ← e^{−dt/τ} b,   Q_b = σ_b² (1 − e^{−2dt/τ}) I₂   (exact discretisation);
//   measure  detected pixel = image of the ball + b_c + white noise (σ_px of the measurement),
// so an image's two viewline rows get the columns ∂(rows)/∂b_c = −√E[Z²] D J (viewline.h's
// derivation: the row residual of a pixel error δ is −Z D J δ; √E[Z²] makes the prior's share
// of the row variance E[Z²] σ_b² D J Jᵀ D, the white term's form). The filter AUGMENTS the
// state to (p, v, b_0, ..., b_{C−1}) (6 + 2C; TrackState::full: coloured measurement noise by
// state augmentation, Simon 2006, Optimal State Estimation, ch. 7) rather than run a Schmidt
// ("consider") filter that would keep the biases at zero and carry only their covariance and
// cross-covariance (Schmidt 1966): two views of one point over-determine it (4
// rows, 3 unknowns), so the part of the biases across the epipolar lines is observable within a
// track, and estimating it gives a smaller, still consistent, (p, v) covariance; with C <= 4 the
// state has at most 14 entries. state(), predictAt() and the NEES a caller computes keep their
// meaning: the (p, v) marginal (the first 6 rows of the lower-triangular square-root factor are
// the factor of the marginal, so it is exact). NIS is that of the image's two rows with S
// including the bias terms.
// The biases restart from their stationary prior N(0, σ_b² I) with every track (seed, restart,
// young-track refit): the calibration / registration part persists across throws, but it is a
// pixel error that depends on where in the image and at what depth the ball is, and throws cross
// different parts of the image; the stationary prior is then still the right (marginal) prior,
// so the filter stays consistent and only forgoes what a previous track said; and a track stays
// a function of its own history, which the restart, the refit and the late-data replay rely on.
// With sigma_px = 0 the state is (p, v) and every operation is the one without the option.
//
// Each processed image reports what happened to it: its outcome carries the track gate's
// decision (Start, Accept, Reject, Restart), and lastUpdate() gives the submitted image's
// innovation, S and NIS as the tracker formed them, so a telemetry sink or a tuning tool reads
// the tracker's own diagnostics instead of recomputing them.

#include <array>
#include <cstdint>
#include <deque>
#include <optional>
#include <unordered_map>
#include <vector>

#include "viewline/core/camera.h"
#include "viewline/core/time.h"
#include "viewline/estimation/state.h"
#include "viewline/tracking/ballistic.h"
#include "viewline/tracking/gates.h"
#include "viewline/tracking/track_gate.h"
#include "viewline/tracking/viewline.h"

namespace viewline::tracking {

/// One detected image point with its capture time.
struct ImageMeasurement {
  std::uint64_t id = 0;          ///< unique per measurement (for outcome queries)
  std::size_t camera = 0;        ///< index into the tracker's cameras
  core::Timestamp t = 0.0;       ///< capture time, s
  Eigen::Vector2d uv = Eigen::Vector2d::Zero();  ///< detected pixel (distorted, as in the image)
  double sigma_px = 0.5;         ///< pixel noise std, px
};

/// Why the tracker refused a measurement (None: accepted for processing).
enum class Refusal : int {
  None = 0,
  NonFinite,      ///< NaN/Inf stamp or pixel
  UnknownCamera,  ///< camera index out of range
  OutsideImage,   ///< pixel outside the image by more than the margin
  BadNoise,       ///< sigma_px not a positive finite number
  Duplicate,      ///< same camera and stamp (or same id) already buffered
  TooOld,         ///< older than newest − late_horizon
  FarFuture,      ///< more than max_forward_gap after the newest stamp
  kCount
};
/// Lower-case name of a refusal ("none", "non_finite", "too_old", ...).
const char* toString(Refusal r);

/// Time handling: exact propagation to every capture time, or a fixed grid with Δt-offset rows ([L] eq 26).
enum class TimeMode { Exact, DtOffset };
/// Lower-case name of a time mode ("exact", "dt_offset").
const char* toString(TimeMode m);

/// What became of a processed image: fused, gated out, or dropped when its track restarted.
enum class Fate { Fused, Gated, DroppedOnRestart };
/// Lower-case name of a fate ("fused", "gated", "dropped_on_restart").
const char* toString(Fate f);

/// The outcome of one processed image: its fate, gate statistics and the track gate's decision.
struct MeasurementOutcome {
  ImageMeasurement m;  ///< the measurement
  Fate fate = Fate::Fused;  ///< fused, gated or dropped
  GateReport gate;  ///< both gates' statistics for the image
  bool seed = false;   ///< started a track (fused without gating)
  /// The track gate's decision when the image was processed: Start for a seed, Accept / Reject
  /// for a fused / gated image, Restart for the rejection that restarted the track (a restart
  /// re-feeds the history, so the outcomes then hold the decisions of the new track).
  GateDecision decision = GateDecision::Start;
};

/// The update's own diagnostics for one submitted image, as the tracker formed them when the
/// image was processed (for the new track's prior when the decision is Start).
struct ImageUpdate {
  ImageMeasurement m;  ///< the measurement
  GateDecision decision = GateDecision::Start;  ///< the track gate's decision
  Eigen::Vector2d innovation = Eigen::Vector2d::Zero();  ///< d = y − C x̂(t|t−) of the image's two viewline rows
  Eigen::Matrix2d S = Eigen::Matrix2d::Identity();       ///< R2 + C P Cᵀ
  Eigen::Matrix2d R = Eigen::Matrix2d::Identity();       ///< R2, the rows' own noise (viewline.h)
  double nis = 0.0;                                      ///< dᵀ S⁻¹ d (GateReport::mahalanobis)
  int fused_before = 0;  ///< fused images of the track the image was tested against (0 for Start)
};

/// Robust track start (track_start.cpp): a new track stays tentative until `confirm_images` images
/// of its window are jointly consistent with the ballistic model, setting aside up to `max_outliers`
/// of them; only a confirmed track is trusted (confirmed()). 0 images: the first image seeds the
/// track untested and the track counts as confirmed at once (the life cycle described above).
struct TrackStartConfig {
  int confirm_images = 0;      ///< M, consistent images a tentative track needs; 0 disables the robust start
  int max_outliers = 2;        ///< images of the window the start may set aside (the subsets it searches)
  std::size_t window = 10;     ///< newest images a tentative track keeps (older ones are dropped)
  double probability = 0.999;  ///< chi-square probability of the joint consistency test of a subset
};

/// Per-camera pixel bias (header comment): a first-order Gauss-Markov process per image axis.
struct PixelBiasConfig {
  double sigma_px = 0.0;          ///< stationary std per axis, px; 0 turns the bias state off
  double time_constant_s = 1.0;   ///< τ, s (correlation e^{−|Δt|/τ}); +infinity: a random constant
  /// Per-camera stationary std, px (one entry per camera, each > 0), e.g. a camera registered to
  /// the robot against one that keeps its calibrated pose; empty: sigma_px for every camera.
  /// Only read when sigma_px > 0.
  std::vector<double> camera_sigma_px;
  /// True when the biases are part of the state.
  bool enabled() const { return sigma_px > 0.0; }
  /// Camera c's stationary std, px.
  double sigmaOf(std::size_t camera) const { return camera_sigma_px.empty() ? sigma_px : camera_sigma_px[camera]; }
};

/// Configuration of the viewline tracker: model, prior, gate, time handling, late-data horizon, restarts and
/// noise model.
struct TrackerConfig {
  BallisticModel model;  ///< ballistic motion model (gravity, acceleration noise)
  Vector6 prior_mean = (Vector6() << 0.0, 0.0, 3.0, 0.0, 0.0, -8.0).finished();  ///< SPEC §2 ([L])
  Matrix6 prior_cov = 100.0 * Matrix6::Identity();                              ///< 10² I
  GateConfig gate;  ///< outlier gate of each image's two rows
  TimeMode time_mode = TimeMode::Exact;  ///< exact propagation or fixed grid
  double sample_period = 0.01;        ///< s, grid of TimeMode::DtOffset
  double late_horizon = 0.2;          ///< s
  double max_forward_gap = 1.0;       ///< s
  int restart_after_rejections = 3;   ///< consecutive gated images of one camera (a fused image
                                      ///< of that camera resets its count)
  double max_coast = 0.5;             ///< s without a fused image: the next one starts a new track
  std::size_t history_capacity = 24;  ///< measurements kept per track for a restart
  double min_depth = 0.05;            ///< m, floor of the predicted depth in the noise model
  bool depth_variance_in_noise = true;  ///< row variance from Ẑ² + σ_Z² (true) or Ẑ² (false)
  /// Young-track refit: while a track has at most this many fused images, after each fused image
  /// the track is re-filtered from its prior over its history with every row's E[Z²] taken from
  /// the CURRENT estimate (propagated back to that capture time) instead of the prediction at the
  /// time. The depth, and so the row noise, is poorly known at first; without the refit the first
  /// rows keep the huge variance of the prior's depth forever (information lost, slow single-camera
  /// convergence). 0 disables it. Causal (uses only the track history), so late replay stays exact.
  int refit_young_tracks = 8;
  double image_margin_px = 0.5;       ///< pixels this far outside the image are still accepted
  TrackStartConfig start;             ///< robust start (off by default: the first image seeds the track)
  PixelBiasConfig pixel_bias;         ///< per-camera pixel-bias state (off by default)
  /// Throws core::InvalidInput naming the field.
  void validate() const;
};

/// Track state: what a snapshot holds (the estimate and the track bookkeeping).
struct TrackState {
  /// A track state with this gate and no estimate yet.
  explicit TrackState(TrackGate g) : gate(std::move(g)) {}
  estimation::StateEstimate est;  ///< the estimate (x = (p, v) world frame, time)
  /// With the pixel bias on: the filter's state (p, v, b_0, ..., b_{C−1}) (px), of which `est`
  /// is the (p, v) marginal; empty (0-dim) otherwise.
  estimation::StateEstimate full;
  /// Life cycle: live track, time of the last fused image, rejections in a row per camera.
  TrackGate gate;
  int fused_in_track = 0;  ///< images fused since the track's seed
  core::Timestamp track_start_t = 0.0;      ///< sample time of the track's prior
  std::vector<MeasurementOutcome> history;  ///< since the track's seed (capped)
  int tracks_started = 0;  ///< tracks started so far (seeds)
  int restarts = 0;  ///< restarts after rejections in a row
  /// False while a robust start (TrackStartConfig) has not yet found a consistent subset of
  /// confirm_images images; always true without the robust start.
  bool confirmed = true;
  int confirmations = 0;  ///< tentative tracks confirmed so far (robust start)
};

/// One image fused into an estimate at the estimate's time + dt_offset: builds the rows, gates
/// them (unless `force`), updates when accepted. The estimate must already be at its sample time.
MeasurementOutcome fuseImage(estimation::StateEstimate& s, const core::Camera& camera,
                             const ImageMeasurement& m, const BallisticModel& model,
                             const GateConfig& gate, double dt_offset, double min_depth, bool force,
                             bool depth_variance_in_noise = true);

/// The multi-view asynchronous viewline tracker ([L]): images of any calibrated camera fused as plane
/// constraints, late images re-processed.
class ViewlineTracker {
public:
  /// Tracker over `cameras` (intrinsics, distortion, c_M_w; validated config, throws core::InvalidInput).
  ViewlineTracker(std::vector<core::Camera> cameras, TrackerConfig cfg);

  /// Validates, buffers and fuses one measurement (re-processing later ones when it is late).
  Refusal submit(const ImageMeasurement& m);

  /// True while a track is live.
  bool initialised() const { return state_.gate.active(); }
  /// True while a live track is confirmed (trusted): always, once live, without the robust start.
  bool confirmed() const { return state_.gate.active() && state_.confirmed; }
  /// The estimate after the newest processed measurement (time = its capture time, or its grid
  /// instant in DtOffset mode).
  const estimation::StateEstimate& state() const { return state_.est; }
  /// The estimate and the track bookkeeping.
  const TrackState& trackState() const { return state_; }
  /// The estimate propagated to t >= state().t() (no measurement fused).
  estimation::StateEstimate predictAt(core::Timestamp t) const;

  /// How many measurements were refused for reason r.
  std::size_t refusalCount(Refusal r) const { return refusals_[static_cast<std::size_t>(r)]; }
  /// How many late measurements were inserted into the buffer (and the later ones re-processed).
  std::size_t lateInserted() const { return late_inserted_; }
  /// Measurements kept in the late-data buffer.
  std::size_t bufferSize() const { return count_; }
  /// The update of the image the last submit() processed (as it was processed then: a later
  /// restart or late insertion may change its outcome); empty when that image was refused.
  const std::optional<ImageUpdate>& lastUpdate() const { return last_update_; }

  /// Current outcome of a processed measurement (it can change while the measurement is within
  /// the horizon or in the current track's history).
  std::optional<MeasurementOutcome> outcome(std::uint64_t id) const;
  /// Outcomes of every processed measurement since the last clearOutcomes().
  std::vector<MeasurementOutcome> outcomes() const;
  /// Forgets the outcomes recorded so far.
  void clearOutcomes() { final_.clear(); }

  /// The cameras of the rig.
  const std::vector<core::Camera>& cameras() const { return cameras_; }
  /// The configuration in use.
  const TrackerConfig& config() const { return cfg_; }
  /// Forget everything (state, buffer, outcomes, counters).
  void reset();

private:
  struct Entry {
    ImageMeasurement m;
    TrackState before;
  };
  Refusal check(const ImageMeasurement& m) const;
  static TrackState initialState(const TrackerConfig& cfg, std::size_t cameras);
  /// One image (stepFilter), then `est` set to the (p, v) marginal of `full` when the pixel bias is on.
  void step(TrackState& ts, const ImageMeasurement& m, ImageUpdate* update);
  void stepFilter(TrackState& ts, const ImageMeasurement& m, ImageUpdate* update);
  /// The state the filter runs on: `full` with the pixel bias, else `est`.
  estimation::StateEstimate& work(TrackState& ts) const;
  /// Time update of a filter state (either form) to t >= its time.
  void predictTo(estimation::StateEstimate& s, core::Timestamp t) const;
  void startTrack(TrackState& ts, core::Timestamp t);
  void restart(TrackState& ts);
  void refit(TrackState& ts) const;
  /// One image of a tentative track (robust start, track_start.cpp).
  void stepTentative(TrackState& ts, const ImageMeasurement& m, ImageUpdate* update, bool seed);
  /// Young-track refit of a confirmed track under the robust start (the start's fixed-point fit).
  void refitConfirmed(TrackState& ts) const;
  /// Restart of a confirmed track under the robust start: tentative again over its newest images.
  void restartTentative(TrackState& ts);
  void evict(const MeasurementOutcome& o);
  /// Late-data buffer entry i (0: the oldest) in the ring.
  Entry& entry(std::size_t i) { return ring_[(head_ + i) % ring_.size()]; }
  /// Late-data buffer entry i (0: the oldest) in the ring.
  const Entry& entry(std::size_t i) const { return ring_[(head_ + i) % ring_.size()]; }
  /// Appends (m, s) to the buffer, copying into a free slot's storage when there is one.
  void pushEntry(const ImageMeasurement& m, const TrackState& s);
  core::Timestamp sampleTime(core::Timestamp t) const;

  std::vector<core::Camera> cameras_;
  TrackerConfig cfg_;
  TrackState fresh_;  ///< no track yet (what reset() returns to)
  TrackState state_;
  std::optional<ImageUpdate> last_update_;
  // The late-data buffer: a ring whose slots keep their storage (a new entry copy-assigns into
  // a slot an old one left, so the steady state does not allocate); count_ entries from head_.
  std::vector<Entry> ring_;
  std::size_t head_ = 0, count_ = 0;
  std::vector<MeasurementOutcome> final_;  ///< outcomes that left the history, sorted by id
  std::array<std::size_t, static_cast<std::size_t>(Refusal::kCount)> refusals_{};
  bool any_ = false;
  core::Timestamp newest_ = 0.0;
  std::size_t late_inserted_ = 0;
};

}  // namespace viewline::tracking
