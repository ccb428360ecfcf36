#include "node_common.h"

#include <sys/resource.h>

#include <algorithm>
#include <cmath>
#include <cstdarg>

#include "viewline/core/interrupt.h"
#include "viewline/io/files.h"

namespace viewline::nodes::detail {

void SimClock::onClock(double t) {
  if (started_ && t < t_) return;  // an older tick delivered late
  t_ = t;
  at_ = std::chrono::steady_clock::now();
  started_ = true;
}

double SimClock::now() const {
  if (!started_) return 0.0;
  return t_ + realtime_ * std::chrono::duration<double>(std::chrono::steady_clock::now() - at_).count();
}

namespace {
dds_domainid_t domainOf(const NodeOptions& opt) {
  return opt.domain < 0 ? DDS_DOMAIN_DEFAULT : static_cast<dds_domainid_t>(opt.domain);
}
}  // namespace

NodeContext::NodeContext(const NodeOptions& o, std::string n, std::string r, std::uint64_t h)
    : opt(o), name(std::move(n)), role(std::move(r)), rig_hash(h), participant(domainOf(o)),
      clock_topic(participant, rosgraph_msgs_msg_dds__Clock__desc, topic::kClock),
      truth_topic(participant, viewline_msg_dds__ObjectTruth__desc, topic::kTruth),
      detection_topic(participant, viewline_msg_dds__Detection__desc, topic::kDetections),
      track_topic(participant, viewline_msg_dds__TrackState__desc, topic::kTrack),
      setpoint_topic(participant, viewline_msg_dds__SetPoint__desc, topic::kSetPoint),
      robot_topic(participant, viewline_msg_dds__RobotState__desc, topic::kRobotState),
      health_topic(participant, viewline_msg_dds__NodeHealth__desc, topic::kHealth),
      episode_topic(participant, viewline_msg_dds__Episode__desc, topic::kEpisode),
      // Deeper than one: health is keyless (ROS 2 style), so one history holds every node's.
      health_writer(participant, health_topic, dds::Qos::health()),
      health_reader(participant, health_topic, dds::Qos(dds::Qos::health()).keepLast(64)),
      wall0_(std::chrono::steady_clock::now()) {}

void NodeContext::publishHealth(HealthStatus s, const std::string& message, double t) {
  NodeHealthMsg m{};
  m.header.stamp = toTimeMsg(t);
  m.header.frame_id = messageString(name);
  m.role = messageString(role);
  m.rig_hash = rig_hash;
  m.status = static_cast<std::uint8_t>(s);
  m.message = messageString(message);
  health_writer.write(m);
}

std::vector<std::string> NodeContext::takeHealth() {
  std::vector<std::string> changed;
  health_reader.take([&](const NodeHealthMsg& m, const dds_sample_info_t&) {
    PeerHealth& p = peers_[m.header.frame_id];
    p.role = m.role;
    p.rig_hash = m.rig_hash;
    p.status = static_cast<HealthStatus>(m.status);
    p.message = m.message;
    changed.push_back(m.header.frame_id);
  });
  return changed;
}

bool NodeContext::worldFinished() const {
  const auto it = peers_.find("world");
  return it != peers_.end() && it->second.status == HealthStatus::Finished;
}

double NodeContext::wallSeconds() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0_).count();
}

bool NodeContext::shouldStop() const { return core::interruptRequested() || wallSeconds() > opt.max_wall_s; }

void NodeContext::log(const char* fmt, ...) const {
  char buf[512];
  va_list ap;
  va_start(ap, fmt);
  std::vsnprintf(buf, sizeof buf, fmt, ap);
  va_end(ap);
  std::fprintf(stderr, "[%s %s] %s\n", role.c_str(), name.c_str(), buf);
  std::fflush(stderr);
}

double quantile(std::vector<double> xs, double p) {
  if (xs.empty()) return 0.0;
  std::sort(xs.begin(), xs.end());
  const auto k = static_cast<std::size_t>(std::ceil(p * static_cast<double>(xs.size())));
  return xs[std::min(xs.size() - 1, k > 0 ? k - 1 : 0)];
}

double processCpuSeconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
         1e-6 * static_cast<double>(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

nlohmann::json finish(const NodeOptions& opt, nlohmann::json summary) {
  if (!opt.summary_path.empty()) io::writeSummaryFile(opt.summary_path, summary);
  return summary;
}

std::string hex(std::uint64_t h) {
  char buf[24];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
  return buf;
}

}  // namespace viewline::nodes::detail
