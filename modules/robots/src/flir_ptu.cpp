#include "viewline/robots/flir_ptu.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>

#include "viewline/core/checks.h"

namespace viewline::robots {

namespace {

using Clock = std::chrono::steady_clock;

std::string joined(const std::vector<std::string>& commands) {
  std::string s;
  for (const auto& c : commands) {
    if (!s.empty()) s += ' ';
    s += c;
  }
  return s;
}

std::string seconds(double s) {
  char b[32];
  std::snprintf(b, sizeof b, "%g s", s);
  return b;
}

bool startsWithNoCase(std::string_view s, std::string_view prefix) {
  if (s.size() < prefix.size()) return false;
  for (std::size_t i = 0; i < prefix.size(); ++i) {
    if (std::toupper(static_cast<unsigned char>(s[i])) != std::toupper(static_cast<unsigned char>(prefix[i]))) return false;
  }
  return true;
}

}  // namespace

void FlirPtuConfig::validate() const {
  if (port.empty() == tcp.empty()) {
    throw core::InvalidInput("FlirPtuConfig: set exactly one of port (serial device) and tcp (host:port)");
  }
  core::requirePositive(reply_timeout, "FlirPtuConfig.reply_timeout");
  core::requireNonNegative(latency, "FlirPtuConfig.latency");
  if (!port.empty() && baud != 9600 && baud != 19200 && baud != 38400 && baud != 57600 && baud != 115200) {
    throw core::InvalidInput("FlirPtuConfig.baud must be 9600, 19200, 38400, 57600 or 115200 (got " + std::to_string(baud) + ")");
  }
}

std::string FlirPtuConfig::describe() const {
  return tcp.empty() ? port + "@" + std::to_string(baud) : "tcp " + tcp;
}

FlirPtuError::FlirPtuError(FlirPtuErrorKind kind, const std::string& what, PtuErrorClass unit_error,
                           PtuLinkErrorKind link_kind)
    : core::Error(what), kind_(kind), unit_error_(unit_error), link_kind_(link_kind) {}

std::unique_ptr<PtuLink> openPtuLink(const FlirPtuConfig& config) {
  config.validate();
  try {
    if (!config.tcp.empty()) {
      const auto [host, port] = parseHostPort(config.tcp);
      return std::make_unique<TcpPtuLink>(host, port, std::max(1.0, config.reply_timeout));
    }
    return std::make_unique<SerialPtuLink>(config.port, config.baud);
  } catch (const PtuLinkError& e) {
    throw FlirPtuError(e.kind() == PtuLinkErrorKind::Timeout ? FlirPtuErrorKind::Timeout : FlirPtuErrorKind::Link,
                       std::string("FLIR PTU: cannot open the link: ") + e.what(), PtuErrorClass::Other, e.kind());
  }
}

FlirPtu::FlirPtu(const FlirPtuConfig& config) : FlirPtu(openPtuLink(config), config) {}

FlirPtu::FlirPtu(std::unique_ptr<PtuLink> link, const FlirPtuConfig& config) : link_(std::move(link)), config_(config) {
  config_.validate();
  if (!link_) throw core::InvalidInput("FlirPtu: no link");
  startUp();
}

FlirPtu::~FlirPtu() { haltBestEffort(); }

std::string FlirPtu::name() const {
  return "FLIR PTU" + (model_.empty() ? std::string() : " (" + model_ + ")") + " on " + link_->port();
}

void FlirPtu::haltBestEffort() noexcept {
  if (!link_) return;
  try {
    // Short deadline: this runs on error paths and in the destructor, which must not hang.
    const double wait = std::min(config_.reply_timeout, 0.25);
    link_->drain();
    link_->write("H ", deadlineIn(wait));
    ++commands_sent_;
    link_->readLine(deadlineIn(wait));
  } catch (...) {  // NOLINT(bugprone-empty-catch): best effort; the caller reports the first failure
  }
}

void FlirPtu::failAndHalt(const FlirPtuError& error) {
  haltBestEffort();
  throw error;
}

std::vector<PtuReply> FlirPtu::exchange(const std::vector<std::string>& commands) {
  const std::string what = "FLIR PTU on " + link_->port() + ", command '" + joined(commands) + "': ";
  std::vector<PtuReply> replies;
  replies.reserve(commands.size());
  last_read_.reset();
  const auto t0 = Clock::now();
  try {
    // Stale bytes (a late reply, an asynchronous message) would be taken for this command's
    // reply and every later exchange would be out of step by one line.
    link_->drain();
    std::string bytes;
    for (const auto& c : commands) bytes += c + ' ';
    link_->write(bytes, deadlineIn(config_.reply_timeout));
    commands_sent_ += commands.size();
    for (std::size_t i = 0; i < commands.size(); ++i) {
      const std::string line = link_->readLine(deadlineIn(config_.reply_timeout));
      PtuReply reply = parsePtuReply(line);
      if (!reply.ok) {
        failAndHalt(FlirPtuError(FlirPtuErrorKind::Unit,
                                 what + "the unit answered '" + commands[i] + "' with an error (" + toString(reply.error) +
                                     "): ! " + reply.text,
                                 reply.error));
      }
      replies.push_back(std::move(reply));
    }
  } catch (const PtuLinkError& e) {
    const bool timeout = e.kind() == PtuLinkErrorKind::Timeout;
    failAndHalt(FlirPtuError(timeout ? FlirPtuErrorKind::Timeout : FlirPtuErrorKind::Link,
                             what + (timeout ? "no reply within " + seconds(config_.reply_timeout) + " (" : "") +
                                 e.what() + (timeout ? ")" : ""),
                             PtuErrorClass::Other, e.kind()));
  } catch (const PtuProtocolError& e) {
    failAndHalt(FlirPtuError(FlirPtuErrorKind::Protocol, what + e.what()));
  }
  last_round_trip_ = std::chrono::duration<double>(Clock::now() - t0).count();
  return replies;
}

void FlirPtu::startUp() {
  const std::string where = "FLIR PTU on " + link_->port() + ", start-up: ";
  // Echo off first. The unit echoes as it receives, so this one reply may still carry the
  // echoed command in front of the '*' ("ED *").
  try {
    link_->drain();
    link_->write("ED ", deadlineIn(config_.reply_timeout));
    ++commands_sent_;
    std::string line = link_->readLine(deadlineIn(config_.reply_timeout));
    std::string_view rest(line);
    while (!rest.empty() && rest.front() == ' ') rest.remove_prefix(1);
    if (startsWithNoCase(rest, "ED")) rest.remove_prefix(2);
    const PtuReply reply = parsePtuReply(rest);
    if (!reply.ok) failAndHalt(FlirPtuError(FlirPtuErrorKind::Unit, where + "ED refused: ! " + reply.text, reply.error));
  } catch (const PtuLinkError& e) {
    failAndHalt(FlirPtuError(e.kind() == PtuLinkErrorKind::Timeout ? FlirPtuErrorKind::Timeout : FlirPtuErrorKind::Link,
                             where + "no answer to ED (echo off): " + e.what() +
                                 (config_.tcp.empty() ? " (check the baud rate: the unit's default is 9600)" : ""),
                             PtuErrorClass::Other, e.kind()));
  } catch (const PtuProtocolError& e) {
    failAndHalt(FlirPtuError(FlirPtuErrorKind::Protocol, where + "answer to ED (echo off): " + e.what()));
  }
  exchange({"FT"});
  model_ = exchange({"V"}).front().text;

  const std::vector<std::string> queries{"PR", "TR", "PN", "PX", "TN", "TX", "PU", "TU", "PA", "TA"};
  const std::vector<PtuReply> r = exchange(queries);
  for (std::size_t i = 0; i < r.size(); ++i) {
    if (!r[i].number || (i >= 2 && !r[i].integer)) {
      failAndHalt(FlirPtuError(FlirPtuErrorKind::Protocol,
                               where + "the reply to " + queries[i] + " holds no " + (i < 2 ? "number" : "integer") +
                                   ": '* " + printableLine(r[i].text) + "'"));
    }
  }
  resolution_ = Eigen::Vector2d(arcsecToRad(*r[0].number), arcsecToRad(*r[1].number));
  const auto steps = [&](std::size_t i) { return static_cast<double>(*r[i].integer); };
  limits_.q_min = Eigen::Vector2d(steps(2) * resolution_(0), steps(4) * resolution_(1));
  limits_.q_max = Eigen::Vector2d(steps(3) * resolution_(0), steps(5) * resolution_(1));
  speed_bound_steps_ = Eigen::Vector2d(steps(6), steps(7));
  limits_.qdot_max = speed_bound_steps_.cwiseProduct(resolution_);
  limits_.qddot_max = Eigen::Vector2d(steps(8) * resolution_(0), steps(9) * resolution_(1));
  try {
    if (!(resolution_.minCoeff() > 0.0)) throw core::InvalidInput("the resolution (PR/TR) must be > 0");
    limits_.validate();
  } catch (const core::InvalidInput& e) {
    failAndHalt(FlirPtuError(FlirPtuErrorKind::Protocol, where + "the unit reported unusable limits: " + e.what()));
  }
  setMode(config_.velocity_mode);
}

void FlirPtu::setMode(bool velocity) {
  exchange({velocity ? "CV" : "CI"});
  velocity_mode_ = velocity;
}

void FlirPtu::commandVelocity(core::Timestamp t, const Eigen::Vector2d& qdot) {
  core::requireFinite(t, "FlirPtu::commandVelocity: t");
  core::requireFinite(qdot, "FlirPtu::commandVelocity: qdot");
  if (t < last_command_t_) throw core::InvalidInput("FlirPtu::commandVelocity: time goes backwards");
  last_command_t_ = t;
  if (!velocity_mode_) setMode(true);
  long long s[2];
  for (int i = 0; i < 2; ++i) {
    const double bound = speed_bound_steps_(i);
    s[i] = std::llround(std::clamp(qdot(i) / resolution_(i), -bound, bound));
  }
  exchange({"PS" + std::to_string(s[0]), "TS" + std::to_string(s[1])});
}

JointState FlirPtu::read(core::Timestamp t) {
  if (last_read_ && last_read_->t == t) return *last_read_;
  static const std::vector<std::string> queries{"PP", "TP", "PD", "TD"};
  const std::vector<PtuReply> r = exchange(queries);
  for (std::size_t i = 0; i < r.size(); ++i) {
    if (!r[i].integer) {
      failAndHalt(FlirPtuError(FlirPtuErrorKind::Protocol, "FLIR PTU on " + link_->port() + ": the reply to " + queries[i] +
                                                               " holds no integer: '* " + printableLine(r[i].text) + "'"));
    }
  }
  JointState s;
  s.t = t;
  s.q = Eigen::Vector2d(static_cast<double>(*r[0].integer) * resolution_(0), static_cast<double>(*r[1].integer) * resolution_(1));
  s.qdot = Eigen::Vector2d(static_cast<double>(*r[2].integer) * resolution_(0), static_cast<double>(*r[3].integer) * resolution_(1));
  last_read_ = s;
  return s;
}

void FlirPtu::stop(core::Timestamp t) {
  core::requireFinite(t, "FlirPtu::stop: t");
  last_command_t_ = std::max(last_command_t_, t);
  halt();
}

void FlirPtu::halt() { exchange({"H"}); }

void FlirPtu::moveTo(const Eigen::Vector2d& q, const Eigen::Vector2d& speed) {
  core::requireFinite(q, "FlirPtu::moveTo: q");
  core::requireFinite(speed, "FlirPtu::moveTo: speed");
  if (!(speed.minCoeff() > 0.0)) throw core::InvalidInput("FlirPtu::moveTo: speed must be > 0 on both axes");
  if (velocity_mode_) setMode(false);
  long long s[2], p[2];
  for (int i = 0; i < 2; ++i) {
    s[i] = std::llround(std::clamp(speed(i) / resolution_(i), 1.0, speed_bound_steps_(i)));
    p[i] = std::llround(q(i) / resolution_(i));
  }
  exchange({"PS" + std::to_string(s[0]), "TS" + std::to_string(s[1]), "PP" + std::to_string(p[0]),
            "TP" + std::to_string(p[1])});
}

void FlirPtu::await(double timeout) {
  core::requirePositive(timeout, "FlirPtu::await: timeout");
  const double saved = config_.reply_timeout;
  config_.reply_timeout = timeout;
  try {
    exchange({"A"});
  } catch (...) {
    config_.reply_timeout = saved;
    throw;
  }
  config_.reply_timeout = saved;
}

}  // namespace viewline::robots
