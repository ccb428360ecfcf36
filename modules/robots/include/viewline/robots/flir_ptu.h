#pragma once
// Driver of the FLIR (Directed Perception) PTU-D46 / E46 / D48E pan-tilt units over their ASCII
// command protocol (flir_ptu_protocol.h), on a serial line or the E-series' TCP port
// (ptu_link.h). Debian's ViSP has no FLIR PTU SDK, so this is viewline's own back end of
// PanTiltUnit; it is tested against FlirPtuEmulator (ptu_emulator.h).
//
// Start-up: drain stale bytes, ED (echo off; its reply may still carry the echo), FT (terse
// feedback), PR/TR (resolution, arc-seconds per position), PN/PX/TN/TX (position limits),
// PU/TU (upper speed bounds), PA/TA (accelerations), then CV (pure velocity mode) or CI
// (independent position mode). Every command is answered by exactly one reply line; before each
// exchange the receive buffer is drained so that a late reply can never be taken for the answer
// to the next command (replies getting out of step is the classic failure of PTU drivers that
// read fixed byte counts).
//
// Failures: a time-out, a garbled reply, a "!" error or a lost link throws FlirPtuError (kind
// and message naming the port and the command), after a best-effort halt (H) with a short
// deadline; the destructor halts too. Units at the interface: rad and rad/s; on the wire:
// positions with the queried resolution.

#include <chrono>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "viewline/robots/flir_ptu_protocol.h"
#include "viewline/robots/pan_tilt_unit.h"
#include "viewline/robots/ptu_link.h"

namespace viewline::robots {

/// How to reach the unit and how long to wait for it.
struct FlirPtuConfig {
  std::string port;               ///< serial device, e.g. /dev/ttyUSB0 (empty when tcp is set)
  int baud = 9600;                ///< serial baud rate (the unit's factory default is 9600)
  std::string tcp;                ///< "host:port" of an E-series unit or the emulator (empty for serial)
  double reply_timeout = 0.5;     ///< s to wait for each reply line (a query takes ~10 ms at 9600 baud)
  double latency = 0.03;          ///< nominal command latency reported to controllers, s
  bool velocity_mode = true;      ///< start in pure velocity mode (CV); false: position mode (CI)

  /// Throws core::InvalidInput naming the field (exactly one of port/tcp, positive time-outs).
  void validate() const;
  /// "port@baud" or "tcp host:port", for messages.
  std::string describe() const;
};

/// What went wrong talking to the unit.
enum class FlirPtuErrorKind {
  Link,      ///< the link failed (missing, busy, permission, disconnected; see linkKind())
  Timeout,   ///< no reply line within reply_timeout
  Protocol,  ///< a reply that is not a PTU reply (garbled, out of step)
  Unit,      ///< the unit answered "!" (see unitError())
};

/// A driver failure. The unit has been sent a halt (best effort) before this is thrown.
class FlirPtuError : public core::Error {
public:
  /// Error of `kind` with message `what`; unit/link detail where it applies.
  FlirPtuError(FlirPtuErrorKind kind, const std::string& what, PtuErrorClass unit_error = PtuErrorClass::Other,
               PtuLinkErrorKind link_kind = PtuLinkErrorKind::Io);
  /// The failure's kind.
  FlirPtuErrorKind kind() const { return kind_; }
  /// For kind Unit: what the "!" reply meant.
  PtuErrorClass unitError() const { return unit_error_; }
  /// For kind Link and Timeout: the link's error kind.
  PtuLinkErrorKind linkKind() const { return link_kind_; }

private:
  FlirPtuErrorKind kind_;
  PtuErrorClass unit_error_;
  PtuLinkErrorKind link_kind_;
};

/// FLIR PTU-D46/E46/D48E over the ASCII protocol; a PanTiltUnit acting "now" on the wall clock.
class FlirPtu : public PanTiltUnit {
public:
  /// Opens the link named by `config` and runs the start-up sequence (throws FlirPtuError,
  /// core::InvalidInput for a bad config).
  explicit FlirPtu(const FlirPtuConfig& config);
  /// Runs the start-up sequence on an open link (tests, custom links).
  FlirPtu(std::unique_ptr<PtuLink> link, const FlirPtuConfig& config);
  /// Halts the unit (best effort, bounded by reply_timeout) and closes the link.
  ~FlirPtu() override;
  FlirPtu(const FlirPtu&) = delete;             ///< owns the link
  FlirPtu& operator=(const FlirPtu&) = delete;  ///< owns the link

  std::string name() const override;
  /// Limits queried at start-up: PN/PX/TN/TX, PU/TU, PA/TA times the resolution.
  const PanTiltLimits& limits() const override { return limits_; }
  double commandLatency() const override { return config_.latency; }
  /// Pure velocity command (switches to CV first when in position mode): PSn TSm in
  /// positions/s, rounded, clipped to the speed bounds. `t` must not go backwards.
  void commandVelocity(core::Timestamp t, const Eigen::Vector2d& qdot) override;
  /// Queries PP TP PD TD (positions and current speeds). The state is stamped t, the request's
  /// time on the caller's clock (as PanTiltUnit::read promises "now"); the unit sampled it up to
  /// lastRoundTrip() later, which is the protocol's share of the measurement latency. Asked again
  /// for the same t with no command in between, it returns that sample without an exchange (a
  /// loop reading the joints at one capture time for several consumers pays the line once).
  JointState read(core::Timestamp t) override;
  /// Halt (H): both axes decelerate to rest.
  void stop(core::Timestamp t) override;

  /// Switches to independent position mode (CI) and moves to q (rad) at `speed` (rad/s per
  /// axis, > 0): PSs TSs PPp TPp. Throws FlirPtuError Unit/PositionLimit outside the limits.
  void moveTo(const Eigen::Vector2d& q, const Eigen::Vector2d& speed);
  /// Waits until a position move is complete (A), up to `timeout` s.
  void await(double timeout);
  /// Halt (H) without a time stamp.
  void halt();
  /// Sends the commands (each followed by a space) in one write and returns their replies in
  /// order; throws FlirPtuError (after a halt) on any failure or "!" reply.
  std::vector<PtuReply> exchange(const std::vector<std::string>& commands);

  /// Resolution (rad per position) of (pan, tilt), as queried.
  const Eigen::Vector2d& resolution() const { return resolution_; }
  /// Whether the unit is in pure velocity mode (CV) rather than position mode (CI).
  bool velocityMode() const { return velocity_mode_; }
  /// Round trip of the last exchange, s.
  double lastRoundTrip() const { return last_round_trip_; }
  /// Number of commands sent since start-up (start-up included).
  std::size_t commandsSent() const { return commands_sent_; }
  /// The configuration in use.
  const FlirPtuConfig& config() const { return config_; }

private:
  void startUp();
  void setMode(bool velocity);
  [[noreturn]] void failAndHalt(const FlirPtuError& error);
  void haltBestEffort() noexcept;
  std::unique_ptr<PtuLink> link_;
  FlirPtuConfig config_;
  PanTiltLimits limits_;
  Eigen::Vector2d resolution_ = Eigen::Vector2d::Zero();
  Eigen::Vector2d speed_bound_steps_ = Eigen::Vector2d::Zero();
  bool velocity_mode_ = false;
  double last_round_trip_ = 0.0;
  std::size_t commands_sent_ = 0;
  core::Timestamp last_command_t_ = -1e300;
  std::optional<JointState> last_read_;  // the last sample, until the next exchange
  std::string model_;
};

/// Opens the link `config` names (serial or TCP).
std::unique_ptr<PtuLink> openPtuLink(const FlirPtuConfig& config);

}  // namespace viewline::robots
