#pragma once
// Telemetry: everything a scenario run reports as it happens, received by sinks.
//
// A scenario loop never writes a CSV file or draws a window itself: it hands records to one
// TelemetrySink, and the app decides what that sink is:
//
//   MemorySink  keeps every record (tuning reads innovations from it: no CSV round trip)
//   CsvSink     writes one CSV per record kind and channel into a log directory
//   FanoutSink  forwards to several sinks (e.g. CSV and a display)
//   TelemetrySink itself ignores everything (the default: batch runs pay nothing)
//
// Records carry their time stamp (the measurement's capture time, the command's issue time) and
// a channel name saying which track, camera or actuator they belong to. An innovation record
// holds the update's own diagnostics (innovation, S, NIS and the gate's decision): consumers read
// them, they never recompute them.

#include <Eigen/Core>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "viewline/tracking/track_gate.h"

namespace viewline::io {
class LogDirectory;
}

namespace viewline::runtime {

/// A measurement as delivered to an estimator (a detected pixel, a table point...).
struct MeasurementRecord {
  std::string channel;           ///< e.g. "camera0", "ball"
  double t = 0.0;                ///< capture time, s
  std::uint64_t id = 0;          ///< measurement id (0: none)
  Eigen::VectorXd z;             ///< the measurement
  Eigen::VectorXd sigma;         ///< its standard deviations (may be empty)
};

/// One gated update of a track: the innovation, its covariance, NIS and the gate's decision.
struct InnovationRecord {
  std::string channel;           ///< the track
  double t = 0.0;                ///< time of the measurement, s
  std::uint64_t id = 0;          ///< measurement id (0: none)
  std::size_t source = 0;        ///< camera / sensor index
  Eigen::Index rows = 0;         ///< measurement rows (the NIS's degrees of freedom), also for Start
  Eigen::VectorXd innovation;    ///< d = z − h(x̂(k|k−1)) (empty when the decision is Start)
  Eigen::MatrixXd S;             ///< innovation covariance
  double nis = 0.0;              ///< dᵀ S⁻¹ d
  /// The gate's decision (accept, reject, start a new track...)
  tracking::GateDecision decision = tracking::GateDecision::Accept;
};

/// A state estimate after an update (or a prediction published to a consumer).
struct EstimateRecord {
  std::string channel;  ///< the track or estimator
  double t = 0.0;  ///< time of the estimate, s
  Eigen::VectorXd x;  ///< the state mean
  Eigen::MatrixXd P;             ///< may be empty
};

/// A command sent to an actuator (joint velocities, a set point...).
struct CommandRecord {
  std::string channel;  ///< the actuator
  double t = 0.0;  ///< issue time, s
  Eigen::VectorXd u;  ///< the command (joint velocities, a set point...)
};

/// A named scalar sample (an error, a flag, a metric's running value).
struct ScalarRecord {
  std::string channel;  ///< e.g. "error_px"
  double t = 0.0;  ///< time of the sample, s
  double value = 0.0;  ///< the value (units in the channel name or the scenario's docs)
};

/// Receives every record of a run. The defaults ignore them.
class TelemetrySink {
public:
  virtual ~TelemetrySink() = default;
  /// A measurement delivered to an estimator (ignored by default).
  virtual void measurement(const MeasurementRecord& /*r*/) {}
  /// One gated update of a track with its diagnostics (ignored by default).
  virtual void innovation(const InnovationRecord& /*r*/) {}
  /// A state estimate (ignored by default).
  virtual void estimate(const EstimateRecord& /*r*/) {}
  /// A command sent to an actuator (ignored by default).
  virtual void command(const CommandRecord& /*r*/) {}
  /// A named scalar sample (ignored by default).
  virtual void scalar(const ScalarRecord& /*r*/) {}
  /// Written files are flushed (end of a run, or before a crash report).
  virtual void flush() {}
};

/// Keeps every record in memory.
class MemorySink : public TelemetrySink {
public:
  void measurement(const MeasurementRecord& r) override { measurements.push_back(r); }
  void innovation(const InnovationRecord& r) override { innovations.push_back(r); }
  void estimate(const EstimateRecord& r) override { estimates.push_back(r); }
  void command(const CommandRecord& r) override { commands.push_back(r); }
  void scalar(const ScalarRecord& r) override { scalars.push_back(r); }

  /// The innovations of one channel (all channels when empty), in arrival order.
  std::vector<InnovationRecord> innovationsOf(const std::string& channel) const;
  /// How many innovations of `channel` (all when empty) had decision d.
  std::size_t count(tracking::GateDecision d, const std::string& channel = {}) const;
  /// Forgets every record.
  void clear();

  std::vector<MeasurementRecord> measurements;  ///< every measurement, in arrival order
  std::vector<InnovationRecord> innovations;  ///< every innovation, in arrival order
  std::vector<EstimateRecord> estimates;  ///< every estimate, in arrival order
  std::vector<CommandRecord> commands;  ///< every command, in arrival order
  std::vector<ScalarRecord> scalars;  ///< every scalar, in arrival order
};

/// Writes records as CSV into a log directory: `<kind>_<channel>.csv`, one row per record, the
/// columns fixed by the first record of the channel (a later record of another size throws).
class CsvSink : public TelemetrySink {
public:
  /// `log` must outlive the sink; a disabled LogDirectory makes every call a no-op.
  explicit CsvSink(io::LogDirectory& log);
  void measurement(const MeasurementRecord& r) override;
  void innovation(const InnovationRecord& r) override;
  void estimate(const EstimateRecord& r) override;
  void command(const CommandRecord& r) override;
  void scalar(const ScalarRecord& r) override;
  void flush() override;

private:
  io::LogDirectory& log_;
};

/// Forwards every record to each of its sinks, in the order added.
class FanoutSink : public TelemetrySink {
public:
  FanoutSink() = default;
  /// Not owned; must outlive the fan-out. Null is ignored.
  void add(TelemetrySink* sink);
  void measurement(const MeasurementRecord& r) override;
  void innovation(const InnovationRecord& r) override;
  void estimate(const EstimateRecord& r) override;
  void command(const CommandRecord& r) override;
  void scalar(const ScalarRecord& r) override;
  void flush() override;

private:
  std::vector<TelemetrySink*> sinks_;
};

}  // namespace viewline::runtime
