#pragma once
// What the pan-tilt loop reports about each frame, beside the generic telemetry records
// (runtime::TelemetrySink: measurements, innovations with the gate's decision, estimates,
// commands). A FrameRecord holds everything one frame produced, image included: a display draws
// it, FrameCsvSink writes it as the `<controller>_frames.csv` log (the columns --replay and the
// tuning tool read), FrameFanout hands it to several.

#include <Eigen/Core>
#include <string>
#include <vector>

#include <opencv2/core/mat.hpp>

namespace viewline::io {
class CsvWriter;
class LogDirectory;
}  // namespace viewline::io

namespace viewline::scenarios::pan_tilt {

/// Everything one frame of the pan-tilt loop produced (screen coordinates in m, pixels in px).
struct FrameRecord {
  std::string controller;                  ///< "predictive" or "visp_baseline"
  const cv::Mat* image = nullptr;          ///< BGR as rendered (valid during the call)
  double t = 0.0;                          ///< capture time, s
  Eigen::Vector2d truth = Eigen::Vector2d::Zero();     ///< target on the screen (m)
  bool detected = false;                   ///< the detector found the disc
  Eigen::Vector2d measured = Eigen::Vector2d::Zero();  ///< detection + [T] noise on the screen (m)
  Eigen::Vector2d filtered = Eigen::Vector2d::Zero();  ///< ours: the filter's estimate (NaN otherwise)
  Eigen::Vector2d truth_px = Eigen::Vector2d::Zero();      ///< the true target in the true camera
  Eigen::Vector2d measured_px = Eigen::Vector2d::Zero();   ///< in the camera the controllers believe in
  bool has_prediction = false;             ///< ours predicted the feature (predicted_px is set)
  Eigen::Vector2d predicted_px = Eigen::Vector2d::Zero();  ///< ŝ at the effect time (NaN without)
  Eigen::Vector2d principal_px = Eigen::Vector2d::Zero();  ///< the true camera's principal point
  double error_px = 0.0;                   ///< |truth − principal point|
  Eigen::Vector2d q = Eigen::Vector2d::Zero(),     ///< joints (pan, tilt) at the command, rad
                  qdot = Eigen::Vector2d::Zero();  ///< joints at the command
  Eigen::Vector2d command = Eigen::Vector2d::Zero();  ///< the joint velocity command (rad/s)
  int mode = 0;                            ///< control::TrackingMode
  std::string mode_name;                   ///< the mode as text (control::toString)
  /// A live source: frames missed so far and the last frame's processing time ("" otherwise).
  std::string live_status;
};

/// Receiver of the loop's FrameRecords (a display, the frames CSV); every hook defaults to nothing.
class FrameSink {
public:
  virtual ~FrameSink() = default;
  /// A run of `controller` starts (before its first frame).
  virtual void runStarted(const std::string& /*controller*/) {}
  /// One frame, in capture order, from the loop's thread; the record is valid during the call.
  virtual void frame(const FrameRecord& /*r*/) {}
  /// The person watching asked to end the run (a display's quit key).
  virtual bool quitRequested() const { return false; }
};

/// `<controller>_frames.csv` in a log directory, exact doubles (17 digits): replayPanTiltFilter and
/// the tuning tool re-run the filter on these measurements.
class FrameCsvSink : public FrameSink {
public:
  /// `log` must outlive the sink; a disabled directory writes nothing.
  explicit FrameCsvSink(io::LogDirectory& log) : log_(log) {}
  void runStarted(const std::string& controller) override;
  void frame(const FrameRecord& r) override;
  /// The CSV's column names, in order (what replayPanTiltFilter reads back).
  static const std::vector<std::string>& columns();

private:
  io::LogDirectory& log_;
  io::CsvWriter* csv_ = nullptr;
};

/// Forwards to each sink in the order added (null ignored; not owned).
class FrameFanout : public FrameSink {
public:
  /// Appends a sink (null: ignored); it must outlive the fan-out.
  void add(FrameSink* sink) {
    if (sink != nullptr) sinks_.push_back(sink);
  }
  /// True when no sink was added.
  bool empty() const { return sinks_.empty(); }
  void runStarted(const std::string& controller) override;
  void frame(const FrameRecord& r) override;
  bool quitRequested() const override;

private:
  std::vector<FrameSink*> sinks_;
};

}  // namespace viewline::scenarios::pan_tilt
