#pragma once
// An emulated FLIR PTU-D46: the unit's ASCII protocol (flir_ptu_protocol.h) served over a
// pseudo-terminal (what a USB-serial adapter looks like to the driver) and a loopback TCP port
// (what an E-series unit looks like), moving in real time (steady clock) with the drive model
// of the simulated unit (predictJointState in pan_tilt_unit.h: acceleration-limited velocity,
// hard stops at the joint limits, an optional command latency).
//
// Commands served: ED/EE/E, FT/FV, V, R, PR/TR, PN/PX/TN/TX, PU/TU, PA/TA, CI/CV/C, PP/TP
// (query; set in position mode), PO/TO, PS/TS (query; set: unsigned speed in position mode,
// signed speed in velocity mode), PD/TD (current speed), H/HP/HT (halt), A (await). Power-up
// state as a real unit: echo on, verbose feedback, position mode.
//
// Faults (setFault) for the driver's tests: no reply (commands act, nothing is answered),
// garbled replies, "!" limit errors on every motion command, a disconnect (the pty / the
// connections are closed), slow replies (a delay before each reply), and an emulated baud rate
// (10 bit times per byte in and out, 8N1).

#include <atomic>
#include <chrono>
#include <cstdint>
#include <deque>
#include <mutex>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "viewline/robots/pan_tilt_unit.h"

namespace viewline::robots {

/// The emulated unit: resolution, limits in positions, drive model.
struct PtuEmulatorParams {
  double pan_resolution_arcsec = 185.1428;   ///< PR, seconds of arc per position (PTU-D46-17)
  double tilt_resolution_arcsec = 185.1428;  ///< TR, seconds of arc per position
  /// Joint, speed and acceleration limits; reported in positions (rounded towards the inside).
  PanTiltLimits limits = PanTiltLimits::flirPtuD46();
  double drive_latency = 0.0;   ///< s between a command's arrival and its effect on the drive
  Eigen::Vector2d q0 = Eigen::Vector2d::Zero();  ///< initial joints, rad
  double tick = 0.002;          ///< s between updates of the motion (and of position-mode servoing)

  /// Throws core::InvalidInput naming the field.
  void validate() const;
};

/// Switchable faults of the emulated unit.
enum class PtuFault {
  None,          ///< behaves
  NoReply,       ///< commands act but get no reply (a broken transmit line)
  GarbledReply,  ///< replies are line noise
  LimitError,    ///< every motion command (PP/TP/PO/TO/PS/TS set) answers "! ... exceeded"
  Disconnect,    ///< the pty and every TCP connection are closed (and new connections refused)
  SlowReply,     ///< every reply waits reply_delay seconds (setReplyDelay)
};

/// FLIR PTU emulator serving the ASCII protocol on a pty and/or a TCP port, on its own thread.
class FlirPtuEmulator {
public:
  /// A unit at rest at params.q0 (validates; throws core::InvalidInput). Call openPty() and/or
  /// listenTcp(), then start().
  explicit FlirPtuEmulator(const PtuEmulatorParams& params = {});
  /// Stops the thread and closes every descriptor.
  ~FlirPtuEmulator();
  FlirPtuEmulator(const FlirPtuEmulator&) = delete;             ///< owns a thread and descriptors
  FlirPtuEmulator& operator=(const FlirPtuEmulator&) = delete;  ///< owns a thread and descriptors

  /// Opens a pseudo-terminal and returns the path of its device end (e.g. /dev/pts/7); before start().
  std::string openPty();
  /// Listens on 127.0.0.1:port (0: any free port) and returns the port; before start().
  int listenTcp(int port = 0);
  /// Starts serving on a thread.
  void start();
  /// Stops serving (idempotent).
  void stop();

  /// Switches a fault on (None: off).
  void setFault(PtuFault fault);
  /// Delay before each reply under PtuFault::SlowReply, s.
  void setReplyDelay(double seconds);
  /// Emulated baud rate (0: no per-byte delay): each byte in and out costs 10 / baud s.
  void setBaud(int baud);

  /// Joint state now (steady clock since construction, s).
  JointState state();
  /// Whether the unit is in pure velocity mode (CV).
  bool velocityMode();
  /// Commands processed so far.
  std::uint64_t commandsHandled() const { return commands_.load(); }
  /// Halt commands (H, HP, HT) received so far.
  std::uint64_t haltsReceived() const { return halts_.load(); }
  /// Resolution (rad per position) of (pan, tilt).
  Eigen::Vector2d resolution() const { return res_; }

  /// Processes one command token (no delimiter) at time t (s, emulator clock) and returns its
  /// reply line without the terminator; empty when the reply is deferred (A while moving).
  /// Exposed for protocol tests on an emulator that was not started; the serving thread calls
  /// it under its lock.
  std::string process(std::string_view command, double t);
  /// Advances the motion to t (s, emulator clock); same rule as process().
  void advance(double t);
  /// Seconds on the emulator clock (steady clock since construction).
  double now() const;

private:
  struct Client {
    int fd = -1;
    bool tcp = false;
    std::string in;
  };
  void run();
  void serveBytes(Client& c, const char* data, std::size_t n);
  void sendReply(Client& c, const std::string& command, const std::string& reply);
  void command(double t, const Eigen::Vector2d& qdot);
  bool moving() const;
  void closeAll();

  PtuEmulatorParams params_;
  Eigen::Vector2d res_;
  Eigen::Vector2d lo_steps_, hi_steps_, speed_bound_, accel_steps_;
  std::chrono::steady_clock::time_point t0_;

  std::mutex mutex_;
  JointState state_;
  std::vector<IssuedCommand> recent_;  // commands still to take effect, plus the active one
  bool velocity_mode_ = false, echo_ = true, terse_ = false;
  Eigen::Vector2d target_steps_ = Eigen::Vector2d::Zero();  // position mode
  Eigen::Vector2d speed_steps_ = Eigen::Vector2d::Zero();   // PS/TS: position-mode speed or velocity-mode command
  bool awaiting_ = false;
  int await_fd_ = -1;  // the client whose A (await) is deferred
  PtuFault fault_ = PtuFault::None;
  double reply_delay_ = 0.0;
  int baud_ = 0;

  // Replies wait here until due: a slow unit or a slow line delays what comes out, not what the
  // unit does (a halt still acts at once).
  struct Outgoing {
    double due;
    int fd;
    bool tcp;
    std::string bytes;
  };
  std::deque<Outgoing> outbox_;
  double line_free_ = 0.0;  // emulator time when the emulated serial line has sent everything queued
  void flushDue(double t);

  int pty_master_ = -1, pty_slave_ = -1, listen_fd_ = -1;
  std::vector<Client> clients_;
  std::atomic<bool> running_{false};
  std::atomic<std::uint64_t> commands_{0}, halts_{0};
  std::thread thread_;
};

/// Parses a fault's name: none, no_reply, garbled, limit_error, disconnect, slow (throws
/// core::InvalidInput listing them).
PtuFault parsePtuFault(const std::string& name);

}  // namespace viewline::robots
