#include "viewline/nodes/dds.h"

#include <cmath>

namespace viewline::nodes::dds {

DdsError::DdsError(const std::string& what, dds_return_t rc)
    : core::Error(what + ": " + dds_strretcode(rc) + " (Cyclone DDS return code " + std::to_string(rc) + ")"),
      rc_(rc) {}

dds_return_t check(dds_return_t rc, const std::string& what) {
  if (rc < 0) throw DdsError(what, rc);
  return rc;
}

std::string loopbackConfig(int max_participants) {
  // Unicast discovery: SPDP goes to the peer's ports for participant indices 0..max (Cyclone's
  // port mapping: 7400 + 250 domain + 10 + 2 index), so every process needs its own index.
  return "<CycloneDDS xmlns=\"https://cdds.io/config\"><Domain Id=\"any\">"
         "<General><Interfaces><NetworkInterface address=\"127.0.0.1\"/></Interfaces>"
         "<AllowMulticast>false</AllowMulticast></General>"
         "<Discovery><ParticipantIndex>auto</ParticipantIndex><MaxAutoParticipantIndex>" +
         std::to_string(max_participants) +
         "</MaxAutoParticipantIndex><Peers><Peer address=\"127.0.0.1\"/></Peers></Discovery>"
         "</Domain></CycloneDDS>";
}

dds_duration_t toDuration(double s) {
  if (!(s > 0.0) || !std::isfinite(s)) return DDS_INFINITY;
  return static_cast<dds_duration_t>(std::llround(s * 1e9));
}

Qos::Qos() : q_(dds_create_qos()) {}
Qos::~Qos() { dds_delete_qos(q_); }
Qos::Qos(const Qos& other) : q_(dds_create_qos()) { dds_copy_qos(q_, other.q_); }
Qos& Qos::operator=(const Qos& other) {
  if (this != &other) dds_copy_qos(q_, other.q_);
  return *this;
}

Qos& Qos::reliable(bool on) {
  // 0.1 s: a reliable write blocks at most that long on a full reader history before failing.
  dds_qset_reliability(q_, on ? DDS_RELIABILITY_RELIABLE : DDS_RELIABILITY_BEST_EFFORT, toDuration(0.1));
  return *this;
}
Qos& Qos::keepLast(int depth) {
  dds_qset_history(q_, DDS_HISTORY_KEEP_LAST, depth);
  return *this;
}
Qos& Qos::transientLocal() {
  dds_qset_durability(q_, DDS_DURABILITY_TRANSIENT_LOCAL);
  return *this;
}
Qos& Qos::deadline(double seconds) {
  dds_qset_deadline(q_, toDuration(seconds));
  return *this;
}
Qos& Qos::liveliness(double seconds) {
  dds_qset_liveliness(q_, DDS_LIVELINESS_AUTOMATIC, toDuration(seconds));
  return *this;
}

Qos Qos::detections(int depth) {
  Qos q;
  q.reliable(false).keepLast(depth);
  return q;
}
Qos Qos::cameraWriter() {
  Qos q = detections();
  q.liveliness(kCameraLeaseS);
  return q;
}
Qos Qos::setpoints(double deadline_s) {
  Qos q;
  q.reliable(true).keepLast(64).deadline(deadline_s);
  return q;
}
Qos Qos::state(int depth) {
  Qos q;
  q.reliable(true).keepLast(depth);
  return q;
}
Qos Qos::health() {
  Qos q;
  q.reliable(true).keepLast(1).transientLocal();
  return q;
}

Entity::~Entity() {
  if (h_ > 0) dds_delete(h_);
}
Entity& Entity::operator=(Entity&& o) noexcept {
  if (this != &o) {
    if (h_ > 0) dds_delete(h_);
    h_ = std::exchange(o.h_, 0);
  }
  return *this;
}

Participant::Participant(dds_domainid_t domain)
    : Entity(check(dds_create_participant(domain, nullptr, nullptr),
                   "dds_create_participant (check CYCLONEDDS_URI and its XML)")) {}

Topic::Topic(const Participant& p, const dds_topic_descriptor_t& desc, const std::string& name)
    : Entity(check(dds_create_topic(p.handle(), &desc, name.c_str(), nullptr, nullptr), "dds_create_topic " + name)),
      name_(name) {}

WaitSet::WaitSet(const Participant& p) : Entity(check(dds_create_waitset(p.handle()), "dds_create_waitset")) {}

void WaitSet::attachData(const Entity& reader) {
  Entity cond(check(dds_create_readcondition(reader.handle(), DDS_ANY_STATE), "dds_create_readcondition"));
  check(dds_waitset_attach(handle(), cond.handle(), cond.handle()), "dds_waitset_attach (data)");
  conditions_.push_back(std::move(cond));
}

void WaitSet::attachStatus(const Entity& reader, std::uint32_t mask) {
  check(dds_set_status_mask(reader.handle(), mask), "dds_set_status_mask");
  check(dds_waitset_attach(handle(), reader.handle(), reader.handle()), "dds_waitset_attach (status)");
}

int WaitSet::wait(double timeout_s) {
  return static_cast<int>(check(dds_waitset_wait(handle(), nullptr, 0, timeout_s > 0.0 ? toDuration(timeout_s) : 0), "dds_waitset_wait"));
}

}  // namespace viewline::nodes::dds
