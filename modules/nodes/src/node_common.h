#pragma once
// What every role shares (private to the module): the participant, the topics, the health
// stream, the simulated clock as a node sees it, logging and the end conditions.

#include <chrono>
#include <cstdio>
#include <map>
#include <string>

#include "viewline/nodes/dds.h"
#include "viewline/nodes/messages.h"
#include "viewline/nodes/roles.h"

namespace viewline::nodes::detail {

/// The world's simulated time as a node sees it: the newest rt/clock sample advanced by the wall
/// time since it arrived (times the real-time factor), so stamps between ticks are not quantised.
class SimClock {
public:
  explicit SimClock(double realtime) : realtime_(realtime) {}
  void onClock(double t);
  bool started() const { return started_; }
  double latest() const { return t_; }
  double now() const;

private:
  double realtime_;
  bool started_ = false;
  double t_ = 0.0;
  std::chrono::steady_clock::time_point at_;
};

/// Another node's health as last heard.
struct PeerHealth {
  std::string role;
  std::uint64_t rig_hash = 0;
  HealthStatus status = HealthStatus::Starting;
  std::string message;
};

/// The participant, every topic, the health writer and reader, and the end conditions.
class NodeContext {
public:
  NodeContext(const NodeOptions& opt, std::string name, std::string role, std::uint64_t rig_hash);
  void publishHealth(HealthStatus s, const std::string& message, double t);
  /// Takes the health samples that arrived; returns the names whose health changed.
  std::vector<std::string> takeHealth();
  const std::map<std::string, PeerHealth>& peers() const { return peers_; }
  /// The world has published Finished.
  bool worldFinished() const;
  /// SIGINT/SIGTERM, or max_wall_s of wall time since the node started.
  bool shouldStop() const;
  double wallSeconds() const;
  /// "[role name] message" on stderr, flushed (one line per event).
  void log(const char* fmt, ...) const __attribute__((format(printf, 2, 3)));

  const NodeOptions& opt;
  std::string name, role;
  std::uint64_t rig_hash;
  dds::Participant participant;
  dds::Topic clock_topic, truth_topic, detection_topic, track_topic, setpoint_topic, robot_topic, health_topic,
      episode_topic;
  dds::Writer<NodeHealthMsg> health_writer;
  dds::Reader<NodeHealthMsg> health_reader;

private:
  std::map<std::string, PeerHealth> peers_;
  std::chrono::steady_clock::time_point wall0_;
};

/// p-quantile of xs (nearest rank; 0 for none).
double quantile(std::vector<double> xs, double p);
/// CPU seconds this process has used (user + system).
double processCpuSeconds();
/// Writes the summary to opt.summary_path (if set) and returns it.
nlohmann::json finish(const NodeOptions& opt, nlohmann::json summary);
/// Hash as a fixed-width hex string (JSON numbers lose 64-bit precision).
std::string hex(std::uint64_t h);

}  // namespace viewline::nodes::detail
