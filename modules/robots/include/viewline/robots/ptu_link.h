#pragma once
// Byte links to a pan-tilt unit's ASCII command port: a serial line (termios, raw 8N1) or a TCP
// client (the E-series units' Ethernet port, and the emulator's loopback port). One interface,
// line-oriented reads with a deadline, and errors that name the port and say what went wrong
// (missing device, busy, no permission, time-out, disconnect), so a driver above never hangs
// and never reports an anonymous I/O failure.
//
// Lines end with '\n'; a '\r' before it is dropped (the units reply "...\r\n").

#include <chrono>
#include <memory>
#include <string>
#include <string_view>

#include "viewline/core/error.h"

namespace viewline::robots {

/// What went wrong on a link (the message says it in words, with the port's name).
enum class PtuLinkErrorKind {
  Missing,       ///< no such device / nothing listening at the address
  Busy,          ///< the device is open (locked) by another process
  Permission,    ///< no permission to open the device (e.g. not in group dialout)
  Timeout,       ///< no complete line before the deadline
  Disconnected,  ///< the other end closed the link (unplugged, emulator gone, TCP reset)
  Io,            ///< any other operating-system error
  BadAddress,    ///< a malformed port spec (baud rate, host:port)
};

/// A link failure; what() names the port and the cause.
class PtuLinkError : public core::Error {
public:
  /// Error of kind `kind` on `port` with the message `what` (already naming the port).
  PtuLinkError(PtuLinkErrorKind kind, std::string port, const std::string& what);
  /// The failure's kind.
  PtuLinkErrorKind kind() const { return kind_; }
  /// The port it happened on (device path or host:port).
  const std::string& port() const { return port_; }

private:
  PtuLinkErrorKind kind_;
  std::string port_;
};

/// Short name of an error kind ("time-out", "disconnected", ...).
const char* toString(PtuLinkErrorKind kind);

/// A bidirectional byte link carrying a line-based ASCII protocol.
class PtuLink {
public:
  /// Steady-clock time point used for deadlines.
  using Deadline = std::chrono::steady_clock::time_point;
  virtual ~PtuLink() = default;
  /// Writes all bytes before `deadline`; throws PtuLinkError (Timeout, Disconnected, Io).
  virtual void write(std::string_view bytes, Deadline deadline) = 0;
  /// Next line without its terminator (a carriage return before the line feed dropped); throws
  /// PtuLinkError Timeout when no full line arrives before `deadline`, Disconnected when the
  /// other end closed.
  virtual std::string readLine(Deadline deadline) = 0;
  /// Discards every byte already received (stale replies), without waiting.
  virtual void drain() = 0;
  /// The port's name for messages (device path or host:port).
  virtual const std::string& port() const = 0;
};

/// Serial line: raw mode, 8 data bits, no parity, 1 stop bit, no flow control, locked for
/// exclusive use (flock + TIOCEXCL). Baud rates 9600, 19200, 38400, 57600, 115200.
class SerialPtuLink : public PtuLink {
public:
  /// Opens `device` at `baud` (throws PtuLinkError: Missing, Busy, Permission, BadAddress, Io).
  SerialPtuLink(const std::string& device, int baud);
  ~SerialPtuLink() override;
  SerialPtuLink(const SerialPtuLink&) = delete;             ///< owns a file descriptor
  SerialPtuLink& operator=(const SerialPtuLink&) = delete;  ///< owns a file descriptor
  void write(std::string_view bytes, Deadline deadline) override;
  std::string readLine(Deadline deadline) override;
  void drain() override;
  const std::string& port() const override { return port_; }

private:
  int fd_ = -1;
  std::string port_, buffer_;
};

/// TCP client (Nagle off: commands are a few bytes and latency matters).
class TcpPtuLink : public PtuLink {
public:
  /// Connects to host:port (numeric IPv4 or a resolvable name) within `connect_timeout` s
  /// (throws PtuLinkError: Missing when refused, Timeout, BadAddress, Io).
  TcpPtuLink(const std::string& host, int port, double connect_timeout = 2.0);
  ~TcpPtuLink() override;
  TcpPtuLink(const TcpPtuLink&) = delete;             ///< owns a socket
  TcpPtuLink& operator=(const TcpPtuLink&) = delete;  ///< owns a socket
  void write(std::string_view bytes, Deadline deadline) override;
  std::string readLine(Deadline deadline) override;
  void drain() override;
  const std::string& port() const override { return port_; }

private:
  int fd_ = -1;
  std::string port_, buffer_;
};

/// Splits "host:port" (throws PtuLinkError BadAddress naming `spec`).
std::pair<std::string, int> parseHostPort(const std::string& spec);

/// Deadline `seconds` from now on the steady clock.
PtuLink::Deadline deadlineIn(double seconds);

}  // namespace viewline::robots
