#pragma once
// A thin RAII layer over Eclipse Cyclone DDS's C API (0.10): participant, topic, writer and
// reader with their QoS, and a waitset with a time-out. Every entity is deleted by its owner's
// destructor (dds_delete), every failing call throws DdsError naming the call and Cyclone's
// return code (dds_strretcode), so a node never runs on with a half-built entity.
//
//   nodes::dds::Participant p;                                    // domain from CYCLONEDDS_URI
//   nodes::dds::Topic t(p, viewline_msg_dds__Detection__desc, "rt/viewline/detections");
//   nodes::dds::Writer<viewline_msg_dds__Detection_> w(p, t, nodes::dds::Qos::detections());
//   nodes::dds::Reader<viewline_msg_dds__Detection_> r(p, t, nodes::dds::Qos::detections());
//   nodes::dds::WaitSet ws(p);  ws.attachData(r);  ws.wait(0.1);
//   r.take([](const viewline_msg_dds__Detection_& d, const dds_sample_info_t& info) { ... });
//
// QoS per stream (Qos::..., one function each; the reason is on each):
//   detections  best-effort, keep-last, volatile; camera writers also assert liveliness
//               (automatic, lease Qos::kCameraLeaseS) so the tracker notices a camera leaving;
//   set points  reliable, keep-last 64, with a deadline on both ends: every set point reaches the
//               robot in order (it interpolates its path between them: one dropped would bend
//               the path), and the robot halts when the tracker goes silent for longer than the
//               deadline;
//   state       reliable keep-last (clock, truth, track, robot state): a late sample is still
//               better than none, the reader keeps the newest few;
//   health      reliable, transient-local, keep-last 1: a node that joins late still sees every
//               other node's health (and its rig hash) at once.

#include <dds/dds.h>

#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "viewline/core/error.h"

namespace viewline::nodes::dds {

/// A failed Cyclone DDS call: the message names the call and Cyclone's return code.
class DdsError : public core::Error {
public:
  /// `what`: the call and its subject (e.g. "dds_create_topic rt/clock"); rc: Cyclone's return code.
  DdsError(const std::string& what, dds_return_t rc);
  /// Cyclone's return code (DDS_RETCODE_...).
  dds_return_t code() const { return rc_; }

private:
  dds_return_t rc_;
};

/// Throws DdsError when rc < 0 (a Cyclone return code or an entity handle); returns rc otherwise.
dds_return_t check(dds_return_t rc, const std::string& what);

/// Cyclone DDS XML for one machine without multicast: the loopback interface, unicast discovery
/// with 127.0.0.1 as the only peer, `max_participants` participant indices probed (one per node
/// process). Put it in a file and point CYCLONEDDS_URI at it (file://...), or pass it inline.
std::string loopbackConfig(int max_participants = 40);

/// Seconds to Cyclone's nanosecond durations (DDS_INFINITY for s <= 0 or infinite).
dds_duration_t toDuration(double s);

/// A QoS policy set (dds_qos_t), owned. Named constructors give each stream's QoS (header comment).
class Qos {
public:
  /// An empty QoS (Cyclone's defaults for every policy).
  Qos();
  /// Frees the policy set.
  ~Qos();
  /// Copies every policy.
  Qos(const Qos& other);
  /// Copies every policy.
  Qos& operator=(const Qos& other);
  /// The underlying dds_qos_t (owned by this object).
  const dds_qos_t* get() const { return q_; }

  /// Reliable (max blocking 0.1 s) or best-effort delivery.
  Qos& reliable(bool on);
  /// Keep the newest `depth` samples (per instance).
  Qos& keepLast(int depth);
  /// Transient-local durability: the writer keeps its history for readers that join later.
  Qos& transientLocal();
  /// Deadline, s: a reader notes a miss when no sample arrives for this long (writer: promise).
  Qos& deadline(double seconds);
  /// Automatic liveliness with lease `seconds`: the participant asserts it, a dead process misses it.
  Qos& liveliness(double seconds);

  /// Lease of a camera writer's liveliness, s: the tracker notices a camera gone within it.
  static constexpr double kCameraLeaseS = 0.5;
  /// Detections: best-effort keep-last `depth` (a late image is worth less than the next one).
  static Qos detections(int depth = 64);
  /// A camera's detection writer: detections() with automatic liveliness (kCameraLeaseS).
  static Qos cameraWriter();
  /// Set points: reliable keep-last 64 (none dropped) with a deadline, s (the robot halts past it).
  static Qos setpoints(double deadline_s);
  /// Clock, truth, track and robot state: reliable keep-last `depth`.
  static Qos state(int depth = 16);
  /// Node health: reliable, transient-local, keep-last 1.
  static Qos health();

private:
  dds_qos_t* q_;
};

/// An owned DDS entity handle (deleted with its children on destruction); move-only.
class Entity {
public:
  /// Takes ownership of handle h (> 0).
  explicit Entity(dds_entity_t h = 0) : h_(h) {}
  /// Deletes the entity (and its children) in Cyclone.
  ~Entity();
  /// Not copyable: one owner per handle.
  Entity(const Entity&) = delete;
  /// Not copyable: one owner per handle.
  Entity& operator=(const Entity&) = delete;
  /// Takes the other's handle.
  Entity(Entity&& o) noexcept : h_(std::exchange(o.h_, 0)) {}
  /// Deletes the own handle, then takes the other's.
  Entity& operator=(Entity&& o) noexcept;
  /// The Cyclone handle.
  dds_entity_t handle() const { return h_; }

private:
  dds_entity_t h_;
};

/// A domain participant; the domain's configuration comes from CYCLONEDDS_URI (or Cyclone's defaults).
class Participant : public Entity {
public:
  /// Joins `domain` (DDS_DOMAIN_DEFAULT: the one CYCLONEDDS_URI configures, else 0).
  explicit Participant(dds_domainid_t domain = DDS_DOMAIN_DEFAULT);
};

/// A topic: name and type (an idlc-generated descriptor).
class Topic : public Entity {
public:
  /// Creates (or finds) topic `name` of type `desc` in participant p.
  Topic(const Participant& p, const dds_topic_descriptor_t& desc, const std::string& name);
  /// The topic's name.
  const std::string& name() const { return name_; }

private:
  std::string name_;
};

/// Matched peers and their changes, as Cyclone counts them.
struct MatchStatus {
  int current = 0;  ///< peers matched now
  int total = 0;    ///< peers ever matched
};

/// A typed data writer of T (an idlc-generated C struct).
template <class T>
class Writer : public Entity {
public:
  /// A writer of topic t with QoS q.
  Writer(const Participant& p, const Topic& t, const Qos& q)
      : Entity(check(dds_create_writer(p.handle(), t.handle(), q.get(), nullptr), "dds_create_writer " + t.name())),
        topic_(t.name()) {}
  /// Publishes one sample (throws DdsError on failure, e.g. a reliable write timing out).
  void write(const T& sample) { check(dds_write(handle(), &sample), "dds_write " + topic_); }
  /// Readers matched so far.
  MatchStatus matched() const {
    dds_publication_matched_status_t s;
    check(dds_get_publication_matched_status(handle(), &s), "dds_get_publication_matched_status " + topic_);
    return {static_cast<int>(s.current_count), static_cast<int>(s.total_count)};
  }

private:
  std::string topic_;
};

/// Liveliness of the writers a reader is matched with (DDS LIVELINESS_CHANGED).
struct LivelinessStatus {
  int alive = 0;          ///< writers alive now
  int not_alive = 0;      ///< writers matched but not alive
  int alive_change = 0;   ///< change of `alive` since the last query
  int not_alive_change = 0;  ///< change of `not_alive` since the last query (> 0: a lease expired)
  dds_instance_handle_t last_writer = 0;  ///< the writer whose change was last
};

/// A typed data reader of T (an idlc-generated C struct).
template <class T>
class Reader : public Entity {
public:
  /// A reader of topic t with QoS q.
  Reader(const Participant& p, const Topic& t, const Qos& q)
      : Entity(check(dds_create_reader(p.handle(), t.handle(), q.get(), nullptr), "dds_create_reader " + t.name())),
        topic_(t.name()) {}
  /// Takes every sample available and calls f(sample, info) for each valid one (invalid samples,
  /// i.e. instance state changes, are skipped); the samples are Cyclone's loans, valid only during
  /// the call. Returns the number of valid samples.
  int take(const std::function<void(const T&, const dds_sample_info_t&)>& f) {
    constexpr int kBatch = 64;
    void* buf[kBatch] = {};
    dds_sample_info_t info[kBatch];
    int valid = 0;
    while (true) {
      const dds_return_t n = check(dds_take(handle(), buf, info, kBatch, kBatch), "dds_take " + topic_);
      for (dds_return_t i = 0; i < n; ++i) {
        if (!info[i].valid_data) continue;
        ++valid;
        f(*static_cast<const T*>(buf[i]), info[i]);
      }
      if (n > 0) check(dds_return_loan(handle(), buf, n), "dds_return_loan " + topic_);
      if (n < kBatch) return valid;
    }
  }
  /// Writers matched so far.
  MatchStatus matched() const {
    dds_subscription_matched_status_t s;
    check(dds_get_subscription_matched_status(handle(), &s), "dds_get_subscription_matched_status " + topic_);
    return {static_cast<int>(s.current_count), static_cast<int>(s.total_count)};
  }
  /// Deadlines missed since the last call (Cyclone resets the change count on each query).
  int deadlinesMissed() const {
    dds_requested_deadline_missed_status_t s;
    check(dds_get_requested_deadline_missed_status(handle(), &s), "dds_get_requested_deadline_missed_status " + topic_);
    return static_cast<int>(s.total_count_change);
  }
  /// Liveliness of the matched writers (resets the change counts).
  LivelinessStatus liveliness() const {
    dds_liveliness_changed_status_t s;
    check(dds_get_liveliness_changed_status(handle(), &s), "dds_get_liveliness_changed_status " + topic_);
    return {static_cast<int>(s.alive_count), static_cast<int>(s.not_alive_count),
            static_cast<int>(s.alive_count_change), static_cast<int>(s.not_alive_count_change),
            s.last_publication_handle};
  }

private:
  std::string topic_;
};

/// A waitset: blocks until an attached reader has data or a status event, or until a time-out.
class WaitSet : public Entity {
public:
  /// A waitset in participant p.
  explicit WaitSet(const Participant& p);
  /// Wakes when reader r has samples.
  void attachData(const Entity& reader);
  /// Wakes on reader r's status events in `mask` (e.g. DDS_REQUESTED_DEADLINE_MISSED_STATUS).
  void attachStatus(const Entity& reader, std::uint32_t mask);
  /// Waits at most `timeout_s` seconds; returns the number of attached conditions triggered (0: time-out).
  int wait(double timeout_s);

private:
  std::vector<Entity> conditions_;
};

}  // namespace viewline::nodes::dds
