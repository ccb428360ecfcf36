#pragma once
// Live mode: a source that delivers frames at its own pace (a camera, or footage played as one),
// and what a loop reports about keeping up with it.
//
// A camera does not wait for the loop. While the loop processes frame k the camera delivers k+1,
// k+2, ...; a loop that fell behind must not work through them one after the other (each result
// would be older than the last, and the lag would grow without bound), so it takes the newest
// frame, and the frames it passed over are dropped: counted, never silently skipped. A V4L2 driver
// does the same when it has no free buffer: the frame is lost, which shows as a gap in the stamps
// (V4l2Source counts those).
//
// PacedSource plays footage (an image sequence, a video, a recording) as such a camera: frame i
// arrives on the wall clock at w0 + (s_i − s_0) / factor (s the stamps, w0 the wall time of the
// first grab). grab() waits for the next frame when none has arrived yet, and otherwise hands out
// the newest frame that has, counting the ones before it as dropped.
//
// ProcessingTimer measures each frame's processing, from the grab to the command it led to: wall
// time on the steady clock and the loop thread's CPU time (CLOCK_THREAD_CPUTIME_ID), without the
// time the loop spends waiting for its scheduler. A frame misses its deadline when it is dropped,
// or when its processing took longer than the deadline (by default one frame period: the time
// until the camera delivers the next frame). LiveReport holds both counts, the deadline used and
// the processing times (median, p99, max), for a scenario's summary.
//
// The wall clock is an interface (WallClock) so that a test can run a paced source with a clock
// it advances itself: the counts are then exact, whatever the load of the machine.

#include <cstdint>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "viewline/runtime/frame_source.h"

namespace viewline::runtime {

/// A monotonic wall clock that can be waited on (steadyWallClock(); tests pass their own).
class WallClock {
public:
  virtual ~WallClock() = default;
  /// Seconds since an arbitrary origin, monotonic.
  virtual double now() const = 0;
  /// Returns once now() >= t (s, same origin); at once when it already is.
  virtual void sleepUntil(double t) = 0;
};

/// std::chrono::steady_clock (CLOCK_MONOTONIC, the clock of V4L2 buffer stamps) as a WallClock.
WallClock& steadyWallClock();

/// A wall clock that moves only when told to: sleepUntil() jumps to the time asked for, advance()
/// adds processing time. Paced runs on it count their missed frames exactly (tests, simulations).
class ManualClock : public WallClock {
public:
  /// A clock reading `origin` (s).
  explicit ManualClock(double origin = 0.0) : t_(origin) {}
  /// The clock's reading, s.
  double now() const override { return t_; }
  /// Jumps to t (s) when t is ahead; never goes back.
  void sleepUntil(double t) override {
    if (t > t_) t_ = t;
  }
  /// Moves the clock on by dt (s).
  void advance(double dt) { t_ += dt; }

private:
  double t_;
};

/// The CPU time the calling thread has used, s (CLOCK_THREAD_CPUTIME_ID).
double threadCpuSeconds();

/// A source that delivers frames at its own pace (a camera; footage played as one) and counts the
/// frames the loop did not take.
class LiveFrameSource : public FrameSource {
public:
  /// Frames delivered so far: handed out, dropped, or lost by the driver.
  virtual std::uint64_t delivered() const = 0;
  /// Frames delivered but never handed out: passed over for a newer one while the loop was busy,
  /// or lost by the camera or driver (a gap in the stamps, a failed read).
  virtual std::uint64_t dropped() const = 0;
  /// Frames handed out more than one frame period after their capture (they waited in a queue).
  virtual std::uint64_t queuedLate() const { return 0; }
  /// What the source is and how it is paced, e.g. "images played at 1x their stamps' rate".
  virtual std::string describe() const = 0;
};

/// Footage (any FrameSource whose nextReadyTime() is the next frame's stamp) played on the wall
/// clock as a live camera: waits for a frame's arrival, hands out the newest arrived frame, counts
/// the frames it passed over as dropped.
class PacedSource : public LiveFrameSource {
public:
  /// Plays `footage` at `factor` times its stamps' rate (> 0) on `clock` (null: steadyWallClock(),
  /// which must then outlive the source); `what` names the footage in describe(). Throws
  /// core::InvalidInput for a null source or a factor that is not > 0.
  PacedSource(std::unique_ptr<FrameSource> footage, double factor, std::string what, WallClock* clock = nullptr);
  /// The footage's camera count.
  std::size_t cameraCount() const override { return footage_->cameraCount(); }
  /// The stamp of the next frame not yet passed over, s (nullopt at the end of the footage); the
  /// frame grab() hands out may be a later one, when newer frames have arrived by then.
  std::optional<core::Timestamp> nextReadyTime() const override { return footage_->nextReadyTime(); }
  /// Waits until the next frame has arrived, then hands out the newest arrived frame (those
  /// before it count as dropped); nullopt when the footage lost the frame or has ended.
  std::optional<Frame> grab() override;
  std::uint64_t delivered() const override { return handed_out_ + dropped_; }
  std::uint64_t dropped() const override { return dropped_; }
  std::string describe() const override;
  /// The wall time (WallClock's origin) frame stamp `stamp` arrives at, s (the first grab sets the origin).
  double arrival(core::Timestamp stamp) const { return wall0_ + (stamp - stamp0_) / factor_; }

private:
  std::unique_ptr<FrameSource> footage_;
  double factor_;
  std::string what_;
  WallClock* clock_;
  bool started_ = false;
  double wall0_ = 0.0, stamp0_ = 0.0;
  std::uint64_t handed_out_ = 0, dropped_ = 0;
};

/// Median, 99th percentile and maximum of one measure of the per-frame processing time, ms.
struct TimeStats {
  double median_ms = 0.0;  ///< median (linear interpolation), ms
  double p99_ms = 0.0;     ///< 99th percentile (linear interpolation, core::percentile), ms
  double max_ms = 0.0;     ///< maximum, ms
};

/// Measures each frame's processing time (wall and thread CPU) and counts the frames past the
/// deadline. A frame's processing may be split into pieces (the loop's capture and control events):
/// resume() and pause() around each piece, finish() after the last one.
class ProcessingTimer {
public:
  /// A frame is late when its processing (wall) took longer than `deadline_s` (> 0, s); `clock`
  /// as for PacedSource (null: steadyWallClock()). Throws core::InvalidInput for a bad deadline.
  explicit ProcessingTimer(double deadline_s, WallClock* clock = nullptr);
  /// Starts, or goes on, timing frame `id` (any key unique among the frames in flight).
  void resume(std::uint64_t id);
  /// Stops timing frame `id` until the next resume() (waiting for the scheduler is not processing).
  void pause(std::uint64_t id);
  /// Stops timing frame `id` and records it (late when its wall time exceeds the deadline).
  void finish(std::uint64_t id);
  /// Frames recorded.
  std::size_t frames() const { return wall_s_.size(); }
  /// Frames whose processing took longer than the deadline.
  std::size_t late() const { return late_; }
  /// The deadline, s.
  double deadline() const { return deadline_s_; }
  /// The last recorded frame's wall time, ms (0 before the first).
  double lastWallMs() const { return wall_s_.empty() ? 0.0 : 1e3 * wall_s_.back(); }
  /// Wall time per frame (steady clock), ms; zeros when no frame was recorded.
  TimeStats wall() const;
  /// Thread CPU time per frame, ms; zeros when no frame was recorded.
  TimeStats cpu() const;

private:
  struct Running {
    double wall = 0.0, cpu = 0.0;  // accumulated, s
    double wall_at = 0.0, cpu_at = 0.0;
    bool running = false;
  };
  double deadline_s_;
  WallClock* clock_;
  std::map<std::uint64_t, Running> in_flight_;
  std::vector<double> wall_s_, cpu_s_;
  std::size_t late_ = 0;
};

/// What a run on a live source reports: the frames the camera delivered, those the loop missed
/// (dropped, or processed past the deadline), the deadline used and the processing times.
struct LiveReport {
  std::string source;            ///< LiveFrameSource::describe()
  double deadline_s = 0.0;       ///< the deadline, s
  std::string deadline_origin;   ///< why this deadline, e.g. "one frame period at 30 fps"
  std::uint64_t delivered = 0;   ///< frames the source delivered
  std::uint64_t processed = 0;   ///< frames processed (grab to command)
  std::uint64_t dropped = 0;     ///< frames delivered but never processed (the loop was busy, or the driver lost them)
  std::uint64_t late = 0;        ///< frames whose processing took longer than the deadline
  std::uint64_t queued_late = 0; ///< frames handed out more than a period after capture (LiveFrameSource::queuedLate)
  TimeStats wall;                ///< processing time per frame, wall clock
  TimeStats cpu;                 ///< processing time per frame, the loop thread's CPU
  /// Frames that missed their deadline: dropped + late.
  std::uint64_t missed() const { return dropped + late; }
};

/// A display's status line while the run goes on (short enough for a 384 px wide image): "missed N
/// of M frames (deadline D ms), last T ms", T the last frame's processing (wall).
std::string liveStatus(const LiveFrameSource& source, const ProcessingTimer& timer);
/// The report of `source` and `timer` after a run; `deadline_origin` says where the deadline came from.
LiveReport liveReport(const LiveFrameSource& source, const ProcessingTimer& timer, const std::string& deadline_origin);
/// The report as JSON (times in ms).
nlohmann::json toJson(const LiveReport& r);
/// One line for a console summary, e.g. "live: 12 of 300 frames missed their 33.3 ms deadline (...)".
std::string summaryLine(const LiveReport& r);
/// Second line: "processing per frame (ms): wall median .. p99 .. max ..; CPU ...".
std::string processingLine(const LiveReport& r);

}  // namespace viewline::runtime
