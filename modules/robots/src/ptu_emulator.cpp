#include "viewline/robots/ptu_emulator.h"

#include <arpa/inet.h>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <fcntl.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <pty.h>
#include <sys/socket.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cstring>
#include <optional>

#include "viewline/core/checks.h"
#include "viewline/robots/flir_ptu_protocol.h"

namespace viewline::robots {

namespace {

using Clock = std::chrono::steady_clock;

void sleepFor(double seconds) {
  if (seconds > 0.0) std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
}

void writeAll(int fd, const std::string& bytes, bool tcp) {
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = tcp ? ::send(fd, bytes.data() + done, bytes.size() - done, MSG_NOSIGNAL)
                          : ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      if (errno == EAGAIN) {
        pollfd p{fd, POLLOUT, 0};
        ::poll(&p, 1, 50);
        continue;
      }
      return;  // the peer went away: its next read tells it
    }
    done += static_cast<std::size_t>(n);
  }
}

std::string fmt(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.4f", v);
  return b;
}

}  // namespace

void PtuEmulatorParams::validate() const {
  core::requirePositive(pan_resolution_arcsec, "PtuEmulatorParams.pan_resolution_arcsec");
  core::requirePositive(tilt_resolution_arcsec, "PtuEmulatorParams.tilt_resolution_arcsec");
  limits.validate();
  core::requireNonNegative(drive_latency, "PtuEmulatorParams.drive_latency");
  core::requirePositive(tick, "PtuEmulatorParams.tick");
  core::requireFinite(q0, "PtuEmulatorParams.q0");
  for (int i = 0; i < 2; ++i) {
    if (q0(i) < limits.q_min(i) || q0(i) > limits.q_max(i)) throw core::InvalidInput("PtuEmulatorParams.q0 is outside the joint limits");
  }
}

PtuFault parsePtuFault(const std::string& name) {
  if (name == "none") return PtuFault::None;
  if (name == "no_reply") return PtuFault::NoReply;
  if (name == "garbled") return PtuFault::GarbledReply;
  if (name == "limit_error") return PtuFault::LimitError;
  if (name == "disconnect") return PtuFault::Disconnect;
  if (name == "slow") return PtuFault::SlowReply;
  throw core::InvalidInput("PTU emulator fault '" + name + "': expected none, no_reply, garbled, limit_error, disconnect or slow");
}

FlirPtuEmulator::FlirPtuEmulator(const PtuEmulatorParams& params) : params_(params), t0_(Clock::now()) {
  params_.validate();
  res_ = Eigen::Vector2d(arcsecToRad(params_.pan_resolution_arcsec), arcsecToRad(params_.tilt_resolution_arcsec));
  // What the unit reports is in whole positions; the emulated mechanics use exactly those
  // values, so that the driver's queried limits are the ones the motion obeys.
  const PanTiltLimits& l = params_.limits;
  for (int i = 0; i < 2; ++i) {
    lo_steps_(i) = std::ceil(l.q_min(i) / res_(i));
    hi_steps_(i) = std::floor(l.q_max(i) / res_(i));
    speed_bound_(i) = std::floor(l.qdot_max(i) / res_(i));
    accel_steps_(i) = std::floor(l.qddot_max(i) / res_(i));
  }
  params_.limits.q_min = lo_steps_.cwiseProduct(res_);
  params_.limits.q_max = hi_steps_.cwiseProduct(res_);
  params_.limits.qdot_max = speed_bound_.cwiseProduct(res_);
  params_.limits.qddot_max = accel_steps_.cwiseProduct(res_);
  params_.limits.validate();
  state_.t = 0.0;
  state_.q = params_.q0;
  for (int i = 0; i < 2; ++i) target_steps_(i) = std::round(params_.q0(i) / res_(i));
  speed_steps_ = Eigen::Vector2d::Constant(1000.0).cwiseMin(speed_bound_);  // the manual's default speed
}

FlirPtuEmulator::~FlirPtuEmulator() {
  stop();
  closeAll();
}

double FlirPtuEmulator::now() const { return std::chrono::duration<double>(Clock::now() - t0_).count(); }

std::string FlirPtuEmulator::openPty() {
  int master = -1, slave = -1;
  std::array<char, 128> name{};
  if (::openpty(&master, &slave, name.data(), nullptr, nullptr) != 0) {
    throw core::Error(std::string("PTU emulator: openpty failed: ") + std::strerror(errno));
  }
  // The device end starts in cooked mode with echo; a driver sets raw mode, but bytes arriving
  // before it does must not be echoed back or line-edited.
  termios tio{};
  ::tcgetattr(slave, &tio);
  ::cfmakeraw(&tio);
  ::tcsetattr(slave, TCSANOW, &tio);
  ::fcntl(master, F_SETFL, ::fcntl(master, F_GETFL) | O_NONBLOCK);
  ::fcntl(master, F_SETFD, FD_CLOEXEC);
  ::fcntl(slave, F_SETFD, FD_CLOEXEC);
  std::lock_guard<std::mutex> lock(mutex_);
  pty_master_ = master;
  pty_slave_ = slave;  // kept open: the master reads EIO whenever no process holds the device end
  clients_.push_back({master, false, {}});
  return name.data();
}

int FlirPtuEmulator::listenTcp(int port) {
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (fd < 0) throw core::Error(std::string("PTU emulator: socket: ") + std::strerror(errno));
  const int one = 1;
  ::setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  addr.sin_port = htons(static_cast<std::uint16_t>(port));
  if (::bind(fd, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) != 0 || ::listen(fd, 4) != 0) {
    const std::string why = std::strerror(errno);
    ::close(fd);
    throw core::Error("PTU emulator: cannot listen on 127.0.0.1:" + std::to_string(port) + ": " + why);
  }
  socklen_t len = sizeof addr;
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &len);
  std::lock_guard<std::mutex> lock(mutex_);
  listen_fd_ = fd;
  return ntohs(addr.sin_port);
}

void FlirPtuEmulator::start() {
  if (running_.exchange(true)) return;
  thread_ = std::thread([this] { run(); });
}

void FlirPtuEmulator::stop() {
  running_ = false;
  if (thread_.joinable()) thread_.join();
}

void FlirPtuEmulator::closeAll() {
  outbox_.clear();
  for (auto& c : clients_) {
    if (c.fd >= 0) ::close(c.fd);
  }
  clients_.clear();
  pty_master_ = -1;
  if (pty_slave_ >= 0) ::close(pty_slave_);
  pty_slave_ = -1;
  if (listen_fd_ >= 0) ::close(listen_fd_);
  listen_fd_ = -1;
}

void FlirPtuEmulator::setFault(PtuFault fault) {
  std::lock_guard<std::mutex> lock(mutex_);
  fault_ = fault;
}

void FlirPtuEmulator::setReplyDelay(double seconds) {
  core::requireNonNegative(seconds, "FlirPtuEmulator::setReplyDelay");
  std::lock_guard<std::mutex> lock(mutex_);
  reply_delay_ = seconds;
}

void FlirPtuEmulator::setBaud(int baud) {
  if (baud < 0) throw core::InvalidInput("FlirPtuEmulator::setBaud: baud must be >= 0");
  std::lock_guard<std::mutex> lock(mutex_);
  baud_ = baud;
}

JointState FlirPtuEmulator::state() {
  std::lock_guard<std::mutex> lock(mutex_);
  return state_;
}

bool FlirPtuEmulator::velocityMode() {
  std::lock_guard<std::mutex> lock(mutex_);
  return velocity_mode_;
}

void FlirPtuEmulator::command(double t, const Eigen::Vector2d& qdot) { recent_.push_back({t, qdot}); }

void FlirPtuEmulator::advance(double t) {
  const PanTiltLimits& l = params_.limits;
  while (state_.t < t - 1e-12) {
    const double h = std::min(params_.tick, t - state_.t);
    if (!velocity_mode_) {
      // Independent position mode: a trapezoidal profile towards the target at the PS/TS
      // speed, braking at the drive's acceleration (v = sqrt(2 a |e|) near the target).
      Eigen::Vector2d c = Eigen::Vector2d::Zero();
      for (int i = 0; i < 2; ++i) {
        const double e = target_steps_(i) * res_(i) - state_.q(i);
        const double a = l.qddot_max(i);
        if (std::abs(e) <= 0.5 * res_(i) && std::abs(state_.qdot(i)) <= a * params_.tick) {
          state_.q(i) = target_steps_(i) * res_(i);  // the stepper holds the commanded position
          state_.qdot(i) = 0.0;
          continue;
        }
        c(i) = std::copysign(std::min(speed_steps_(i) * res_(i), std::sqrt(2.0 * a * std::abs(e))), e);
      }
      // The unit's own position loop acts at once: the drive latency is that of host commands.
      recent_.assign(1, IssuedCommand{state_.t, c});
      state_ = predictJointState(l, state_, recent_, 0.0, state_.t + h);
    } else {
      state_ = predictJointState(l, state_, recent_, params_.drive_latency, state_.t + h);
    }
    for (int i = 0; i < 2; ++i) {  // hard stops
      if ((state_.q(i) >= l.q_max(i) && state_.qdot(i) > 0.0) || (state_.q(i) <= l.q_min(i) && state_.qdot(i) < 0.0)) {
        state_.qdot(i) = 0.0;
      }
    }
    // Keep the command in effect and the ones still in flight.
    std::size_t active = 0;
    for (std::size_t k = 0; k < recent_.size(); ++k) {
      if (recent_[k].t + params_.drive_latency <= state_.t + 1e-12) active = k;
    }
    recent_.erase(recent_.begin(), recent_.begin() + static_cast<std::ptrdiff_t>(active));
  }
}

bool FlirPtuEmulator::moving() const {
  // A position move is over when both axes rest at their targets (within half a position).
  return !velocity_mode_ && ((target_steps_.cwiseProduct(res_) - state_.q).cwiseAbs().maxCoeff() > 0.5 * res_.maxCoeff() ||
                             state_.qdot.cwiseAbs().maxCoeff() > 0.0);
}

std::string FlirPtuEmulator::process(std::string_view token, double t) {
  advance(t);
  ++commands_;
  std::string cmd;
  std::size_t i = 0;
  for (; i < token.size() && std::isalpha(static_cast<unsigned char>(token[i])); ++i) {
    cmd += static_cast<char>(std::toupper(static_cast<unsigned char>(token[i])));
  }
  const std::string_view arg_text = token.substr(i);
  std::optional<long long> arg;
  if (!arg_text.empty()) {
    std::size_t j = (arg_text[0] == '-' || arg_text[0] == '+') ? 1 : 0;
    const bool digits = j < arg_text.size() && arg_text.size() - j <= 9 &&
                        std::all_of(arg_text.begin() + static_cast<std::ptrdiff_t>(j), arg_text.end(),
                                    [](char c) { return c >= '0' && c <= '9'; });
    if (!digits || cmd.empty()) return "! Illegal argument";
    arg = std::stoll(std::string(arg_text));
  }
  const auto ok = [](const std::string& value = {}) { return value.empty() ? std::string("*") : "* " + value; };
  const auto verbose = [&](const std::string& sentence, const std::string& value) {
    return terse_ ? ok(value) : "* " + sentence;
  };
  const int axis = (!cmd.empty() && cmd[0] == 'T') ? 1 : 0;
  const char* axis_name = axis == 0 ? "Pan" : "Tilt";
  const bool motion_set = arg && (cmd == "PP" || cmd == "TP" || cmd == "PO" || cmd == "TO" || cmd == "PS" || cmd == "TS");
  if (motion_set && fault_ == PtuFault::LimitError) {
    return std::string("! Maximum allowable ") + axis_name + " position exceeded";
  }
  const auto steps = [&](double rad) { return std::to_string(std::llround(rad / res_(axis))); };

  if (cmd == "ED" || cmd == "EE") {
    echo_ = cmd == "EE";
    return ok();
  }
  if (cmd == "E") return verbose(echo_ ? "Echoing ON" : "Echoing OFF", echo_ ? "E" : "D");
  if (cmd == "FT" || cmd == "FV") {
    terse_ = cmd == "FT";
    return ok();
  }
  if (cmd == "V") return ok("viewline FLIR PTU emulator, PTU-D46 protocol");
  if (cmd == "R") return ok();
  if ((cmd == "PR" || cmd == "TR") && !arg) {
    const double arcsec = axis == 0 ? params_.pan_resolution_arcsec : params_.tilt_resolution_arcsec;
    return verbose(fmt(arcsec) + " seconds arc per " + axis_name + " position", fmt(arcsec));
  }
  if ((cmd == "PN" || cmd == "PX" || cmd == "TN" || cmd == "TX") && !arg) {
    const bool min = cmd[1] == 'N';
    const std::string v = std::to_string(std::llround(min ? lo_steps_(axis) : hi_steps_(axis)));
    return verbose(std::string(min ? "Minimum " : "Maximum ") + axis_name + " position is " + v, v);
  }
  if ((cmd == "PU" || cmd == "TU") && !arg) {
    const std::string v = std::to_string(std::llround(speed_bound_(axis)));
    return verbose(std::string("Maximum ") + axis_name + " speed is " + v + " positions/sec", v);
  }
  if ((cmd == "PA" || cmd == "TA") && !arg) {
    const std::string v = std::to_string(std::llround(accel_steps_(axis)));
    return verbose(std::string(axis_name) + " acceleration is " + v + " positions/sec^2", v);
  }
  if (cmd == "CI" || cmd == "CV") {
    const bool v = cmd == "CV";
    if (v != velocity_mode_) {
      velocity_mode_ = v;
      if (v) {
        speed_steps_.setZero();  // entering velocity mode: hold still until a speed is commanded
        command(t, Eigen::Vector2d::Zero());
      } else {
        for (int k = 0; k < 2; ++k) target_steps_(k) = std::round(state_.q(k) / res_(k));
        speed_steps_ = Eigen::Vector2d::Constant(1000.0).cwiseMin(speed_bound_);
      }
    }
    return ok();
  }
  if (cmd == "C") return verbose(velocity_mode_ ? "Pure velocity mode" : "Independent position mode", velocity_mode_ ? "V" : "I");
  if (cmd == "PP" || cmd == "TP" || cmd == "PO" || cmd == "TO") {
    if (!arg) {
      const std::string v = steps(state_.q(axis));
      return verbose(std::string("Current ") + axis_name + " position is " + v, v);
    }
    if (velocity_mode_) return "! Illegal command: position command in pure velocity mode";
    const double target = cmd[1] == 'O' ? target_steps_(axis) + static_cast<double>(*arg) : static_cast<double>(*arg);
    if (target > hi_steps_(axis)) return std::string("! Maximum allowable ") + axis_name + " position exceeded";
    if (target < lo_steps_(axis)) return std::string("! Minimum allowable ") + axis_name + " position exceeded";
    target_steps_(axis) = target;
    return ok();
  }
  if (cmd == "PS" || cmd == "TS") {
    if (!arg) {
      const std::string v = std::to_string(std::llround(speed_steps_(axis)));
      return verbose(std::string("Desired ") + axis_name + " speed is " + v + " positions/sec", v);
    }
    const double s = static_cast<double>(*arg);
    if (std::abs(s) > speed_bound_(axis)) return std::string("! Maximum allowable ") + axis_name + " speed exceeded";
    if (!velocity_mode_ && s < 0.0) return "! Illegal argument: negative speed in position mode";
    speed_steps_(axis) = s;
    if (velocity_mode_) command(t, speed_steps_.cwiseProduct(res_));
    return ok();
  }
  if ((cmd == "PD" || cmd == "TD") && !arg) {
    const std::string v = steps(state_.qdot(axis));
    return verbose(std::string("Current ") + axis_name + " speed is " + v + " positions/sec", v);
  }
  if ((cmd == "H" || cmd == "HP" || cmd == "HT") && !arg) {
    ++halts_;
    for (int k = 0; k < 2; ++k) {
      if ((cmd == "HP" && k == 1) || (cmd == "HT" && k == 0)) continue;
      if (velocity_mode_) {
        speed_steps_(k) = 0.0;
      } else {  // stop where braking at the drive's acceleration ends
        const double v = state_.qdot(k);
        const double stop_at = state_.q(k) + v * std::abs(v) / (2.0 * params_.limits.qddot_max(k));
        target_steps_(k) = std::clamp(std::round(stop_at / res_(k)), lo_steps_(k), hi_steps_(k));
      }
    }
    if (velocity_mode_) command(t, speed_steps_.cwiseProduct(res_));
    return ok();
  }
  if (cmd == "A" && !arg) {
    if (moving()) {
      awaiting_ = true;
      return {};
    }
    return ok();
  }
  return "! Illegal command";
}

void FlirPtuEmulator::sendReply(Client& c, const std::string& command, const std::string& reply) {
  PtuFault fault;
  double delay;
  int baud;
  bool echo;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    fault = fault_;
    delay = reply_delay_;
    baud = baud_;
    echo = echo_ || command == "ED" || command == "ed";  // ED's own bytes were echoed as they arrived
  }
  std::string out = echo ? command + " " : std::string();
  if (fault == PtuFault::GarbledReply) {
    out += "\x15#\xA7~?\x03Q\r\n";  // what a wrong baud rate or a noisy line looks like
  } else {
    out += reply + "\r\n";
  }
  if (fault == PtuFault::NoReply) return;
  std::lock_guard<std::mutex> lock(mutex_);
  const double t = now();
  double due = t;
  // Serial line rate: the command's bytes (and delimiter) in, the reply's bytes out, 10 bits
  // each (8N1), one after the other on the line.
  if (baud > 0) {
    due = std::max(t, line_free_) + static_cast<double>(command.size() + 1 + out.size()) * 10.0 / baud;
    line_free_ = due;
  }
  if (fault == PtuFault::SlowReply) due += delay;
  if (!outbox_.empty()) due = std::max(due, outbox_.back().due);  // replies keep their order
  outbox_.push_back({due, c.fd, c.tcp, std::move(out)});
}

void FlirPtuEmulator::flushDue(double t) {
  while (!outbox_.empty() && outbox_.front().due <= t) {
    const Outgoing o = std::move(outbox_.front());
    outbox_.pop_front();
    writeAll(o.fd, o.bytes, o.tcp);
  }
}

void FlirPtuEmulator::serveBytes(Client& c, const char* data, std::size_t n) {
  c.in.append(data, n);
  if (c.in.size() > 4096) c.in.clear();  // no delimiter in 4 kB: noise, not commands
  std::size_t start = 0;
  for (std::size_t k = 0; k < c.in.size(); ++k) {
    const char ch = c.in[k];
    if (ch != ' ' && ch != '\r' && ch != '\n') continue;
    const std::string token = c.in.substr(start, k - start);
    start = k + 1;
    if (token.empty()) continue;
    std::string reply;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      reply = process(token, now());
      if (reply.empty()) await_fd_ = c.fd;
    }
    if (!reply.empty()) sendReply(c, token, reply);
  }
  c.in.erase(0, start);
}

void FlirPtuEmulator::run() {
  while (running_) {
    std::vector<pollfd> fds;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (fault_ == PtuFault::Disconnect && (!clients_.empty() || listen_fd_ >= 0)) closeAll();
      for (const auto& c : clients_) fds.push_back({c.fd, POLLIN, 0});
      if (listen_fd_ >= 0) fds.push_back({listen_fd_, POLLIN, 0});
    }
    // ppoll: the next reply may be due in a fraction of a millisecond (one byte at 115200 baud
    // is 87 µs); poll's millisecond time-out would round every exchange up.
    double wait = params_.tick;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (!outbox_.empty()) wait = std::clamp(outbox_.front().due - now(), 0.0, wait);
    }
    timespec timeout{};
    timeout.tv_sec = static_cast<time_t>(wait);
    timeout.tv_nsec = static_cast<long>((wait - static_cast<double>(timeout.tv_sec)) * 1e9);
    const int ready = ::ppoll(fds.data(), static_cast<nfds_t>(fds.size()), &timeout, nullptr);
    {
      std::lock_guard<std::mutex> lock(mutex_);
      advance(now());
      flushDue(now());
    }
    // A deferred A (await) is answered once the move has ended.
    {
      std::unique_lock<std::mutex> lock(mutex_);
      if (awaiting_ && !moving()) {
        awaiting_ = false;
        const int fd = await_fd_;
        lock.unlock();
        for (auto& c : clients_) {
          if (c.fd == fd) sendReply(c, "A", "*");
        }
      }
    }
    if (ready <= 0) continue;
    std::array<char, 512> buf{};
    for (const auto& p : fds) {
      if (!(p.revents & (POLLIN | POLLHUP | POLLERR))) continue;
      if (p.fd == listen_fd_) {
        const int fd = ::accept4(listen_fd_, nullptr, nullptr, SOCK_NONBLOCK | SOCK_CLOEXEC);
        if (fd >= 0) {
          const int one = 1;
          ::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
          std::lock_guard<std::mutex> lock(mutex_);
          clients_.push_back({fd, true, {}});
        }
        continue;
      }
      auto it = std::find_if(clients_.begin(), clients_.end(), [&](const Client& c) { return c.fd == p.fd; });
      if (it == clients_.end()) continue;
      const ssize_t n = ::read(it->fd, buf.data(), buf.size());
      if (n > 0) {
        serveBytes(*it, buf.data(), static_cast<std::size_t>(n));
      } else if (it->tcp && (n == 0 || (errno != EAGAIN && errno != EINTR))) {
        std::lock_guard<std::mutex> lock(mutex_);
        const int gone = it->fd;
        outbox_.erase(std::remove_if(outbox_.begin(), outbox_.end(), [&](const Outgoing& o) { return o.fd == gone; }),
                      outbox_.end());
        ::close(gone);
        clients_.erase(it);
      } else if (!it->tcp && n < 0 && errno == EIO) {
        // The pty's device end is closed by the driver (our own handle keeps it from
        // happening, but a hang-up may still be reported): wait a tick instead of spinning.
        sleepFor(params_.tick);
      }
    }
  }
}

}  // namespace viewline::robots
