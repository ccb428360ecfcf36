// FLIR PTU driver against the in-process emulator (pty and TCP), the reply parser, the link's
// errors, and every emulated fault: each must end in a FlirPtuError of the right kind within a
// bounded time, after a halt reached the unit, never in a crash or a hang.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <fcntl.h>
#include <memory>
#include <thread>
#include <unistd.h>

#include "viewline/core/error.h"
#include "viewline/robots/flir_ptu.h"
#include "viewline/robots/flir_ptu_protocol.h"
#include "viewline/robots/ptu_emulator.h"
#include "viewline/robots/ptu_link.h"

using namespace viewline;
using namespace viewline::robots;
using Clock = std::chrono::steady_clock;

namespace {

double secondsSince(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

void sleepSeconds(double s) { std::this_thread::sleep_for(std::chrono::duration<double>(s)); }

// Emulator on its thread with a pty and a TCP port; a driver config for either.
struct Rig {
  FlirPtuEmulator emu;
  std::string pty;
  int tcp_port = 0;
  explicit Rig(const PtuEmulatorParams& p = {}) : emu(p) {
    pty = emu.openPty();
    tcp_port = emu.listenTcp(0);
    emu.start();
  }
  FlirPtuConfig serial(double timeout = 0.3) const {
    FlirPtuConfig c;
    c.port = pty;
    c.baud = 115200;
    c.reply_timeout = timeout;
    return c;
  }
  FlirPtuConfig tcp(double timeout = 0.3) const {
    FlirPtuConfig c;
    c.tcp = "127.0.0.1:" + std::to_string(tcp_port);
    c.reply_timeout = timeout;
    return c;
  }
};

void expectStartedUp(const FlirPtu& ptu, const FlirPtuEmulator& emu) {
  const PanTiltLimits d46 = PanTiltLimits::flirPtuD46();
  const Eigen::Vector2d res = emu.resolution();
  EXPECT_NEAR(ptu.resolution()(0), res(0), 1e-12);
  EXPECT_NEAR(ptu.resolution()(1), res(1), 1e-12);
  for (int i = 0; i < 2; ++i) {  // whole positions, rounded towards the inside
    EXPECT_LE(d46.q_min(i), ptu.limits().q_min(i));
    EXPECT_GT(d46.q_min(i) + res(i), ptu.limits().q_min(i));
    EXPECT_GE(d46.q_max(i), ptu.limits().q_max(i));
    EXPECT_LT(d46.q_max(i) - res(i), ptu.limits().q_max(i));
    EXPECT_NEAR(ptu.limits().qdot_max(i), d46.qdot_max(i), res(i));
    EXPECT_NEAR(ptu.limits().qddot_max(i), d46.qddot_max(i), res(i));
  }
  EXPECT_TRUE(ptu.velocityMode());
  EXPECT_NE(ptu.name().find("emulator"), std::string::npos) << ptu.name();
}

}  // namespace

// --- reply parser --------------------------------------------------------------------------

TEST(PtuReplyParser, TerseAndVerboseReplies) {
  const PtuReply a = parsePtuReply("* 22");
  EXPECT_TRUE(a.ok);
  ASSERT_TRUE(a.integer);
  EXPECT_EQ(*a.integer, 22);
  const PtuReply b = parsePtuReply("* Current Pan position is -500");
  ASSERT_TRUE(b.integer);
  EXPECT_EQ(*b.integer, -500);
  const PtuReply c = parsePtuReply("* 185.1428 seconds arc per Pan position");
  ASSERT_TRUE(c.number);
  EXPECT_DOUBLE_EQ(*c.number, 185.1428);
  EXPECT_FALSE(c.integer);
  const PtuReply d = parsePtuReply("*");
  EXPECT_TRUE(d.ok);
  EXPECT_FALSE(d.number);
  EXPECT_TRUE(parsePtuReply("  *  ").ok);
}

TEST(PtuReplyParser, ErrorRepliesAreClassified) {
  const PtuReply a = parsePtuReply("! Maximum allowable Pan position exceeded");
  EXPECT_FALSE(a.ok);
  EXPECT_EQ(a.error, PtuErrorClass::PositionLimit);
  EXPECT_EQ(parsePtuReply("! Maximum allowable Tilt speed exceeded").error, PtuErrorClass::SpeedLimit);
  EXPECT_EQ(parsePtuReply("!P").error, PtuErrorClass::LimitHit);
  EXPECT_EQ(parsePtuReply("! Illegal command").error, PtuErrorClass::IllegalCommand);
  EXPECT_EQ(parsePtuReply("! Illegal argument").error, PtuErrorClass::IllegalArgument);
  EXPECT_EQ(parsePtuReply("! something else").error, PtuErrorClass::Other);
}

TEST(PtuReplyParser, GarbageIsRejectedWithThePrintableLine) {
  for (const std::string& bad : {std::string(""), std::string("PP"), std::string("\x15#\xA7~?"), std::string("# 12"),
                                std::string(300, '*'), std::string("* 1\x01")}) {
    try {
      parsePtuReply(bad);
      ADD_FAILURE() << "accepted '" << printableLine(bad) << "'";
    } catch (const PtuProtocolError& e) {
      EXPECT_NE(std::string(e.what()).find("PTU reply"), std::string::npos);
    }
  }
  EXPECT_EQ(printableLine("\x15#"), "\\x15#");
  // Not read as numbers: exponents, inf, nan, absurdly long digit strings.
  EXPECT_FALSE(parsePtuReply("* inf").number);
  EXPECT_FALSE(parsePtuReply("* 1234567890123456789012").number);
}

// --- emulator protocol (no thread) -----------------------------------------------------------

TEST(FlirPtuEmulator, ProtocolRepliesAndPositionMove) {
  FlirPtuEmulator emu;
  EXPECT_EQ(emu.process("PP", 0.0), "* Current Pan position is 0");  // power-up: verbose
  EXPECT_EQ(emu.process("FT", 0.0), "*");
  EXPECT_EQ(emu.process("pr", 0.0), "* 185.1428");
  EXPECT_EQ(emu.process("PX", 0.0), "* 2916");  // 150° / 0.0514285° per position, inside
  EXPECT_EQ(emu.process("PP9999", 0.0), "! Maximum allowable Pan position exceeded");
  EXPECT_EQ(emu.process("TP-9999", 0.0), "! Minimum allowable Tilt position exceeded");
  EXPECT_EQ(emu.process("XY", 0.0), "! Illegal command");
  EXPECT_EQ(emu.process("PP12a", 0.0), "! Illegal argument");
  EXPECT_EQ(emu.process("PP500", 0.0), "*");
  EXPECT_EQ(emu.process("A", 0.0), "");  // deferred while moving
  emu.advance(2.0);
  EXPECT_EQ(emu.process("PP", 2.0), "* 500");
  EXPECT_EQ(emu.process("PD", 2.0), "* 0");
  EXPECT_EQ(emu.process("A", 2.0), "*");
  EXPECT_EQ(emu.process("PS99999", 2.0), "! Maximum allowable Pan speed exceeded");
  EXPECT_EQ(emu.process("CV", 2.0), "*");
  EXPECT_EQ(emu.process("PP0", 2.0).substr(0, 17), "! Illegal command");
}

TEST(FlirPtuEmulator, PositionMoveSettlesWithADriveLatency) {
  // The latency delays host commands, not the unit's own position loop: a move still ends.
  PtuEmulatorParams p;
  p.drive_latency = 0.03;
  FlirPtuEmulator emu(p);
  emu.process("FT", 0.0);
  EXPECT_EQ(emu.process("PP-700", 0.0), "*");
  EXPECT_EQ(emu.process("A", 0.0), "");
  emu.advance(3.0);
  EXPECT_EQ(emu.process("PP", 3.0), "* -700");
  EXPECT_EQ(emu.process("A", 3.0), "*");
  // In velocity mode the command acts after the latency.
  emu.process("CV", 3.0);
  emu.process("PS1000", 3.0);
  emu.advance(3.025);
  EXPECT_EQ(emu.state().qdot(0), 0.0);
  emu.advance(3.2);
  EXPECT_NEAR(emu.state().qdot(0), 1000 * emu.resolution()(0), 1e-9);
}

TEST(FlirPtuEmulator, VelocityModeStopsAtTheHardLimit) {
  PtuEmulatorParams p;
  FlirPtuEmulator emu(p);
  emu.process("FT", 0.0);
  emu.process("CV", 0.0);
  emu.process("PS5000", 0.0);
  emu.advance(3.0);  // 257°/s for 3 s: far beyond +150°
  const JointState s = emu.state();
  EXPECT_NEAR(s.q(0), 2916 * emu.resolution()(0), 1e-9);
  EXPECT_EQ(s.qdot(0), 0.0);
}

// --- links ------------------------------------------------------------------------------------

TEST(PtuLink, MissingDeviceIsNamed) {
  try {
    SerialPtuLink link("/dev/ttyViewlineNoSuchPort", 9600);
    FAIL() << "opened a missing device";
  } catch (const PtuLinkError& e) {
    EXPECT_EQ(e.kind(), PtuLinkErrorKind::Missing);
    EXPECT_NE(std::string(e.what()).find("/dev/ttyViewlineNoSuchPort"), std::string::npos) << e.what();
  }
}

TEST(PtuLink, BadBaudAndAddressAreNamed) {
  Rig rig;
  EXPECT_THROW(SerialPtuLink(rig.pty, 12345), PtuLinkError);
  EXPECT_THROW(parseHostPort("localhost"), PtuLinkError);
  EXPECT_THROW(parseHostPort("127.0.0.1:99999"), PtuLinkError);
  EXPECT_EQ(parseHostPort("127.0.0.1:4000").second, 4000);
  FlirPtuConfig both = rig.serial();
  both.tcp = "127.0.0.1:1";
  EXPECT_THROW(FlirPtu{both}, core::InvalidInput);
}

TEST(PtuLink, BusyDeviceIsNamed) {
  Rig rig;
  SerialPtuLink first(rig.pty, 115200);
  try {
    SerialPtuLink second(rig.pty, 115200);
    FAIL() << "opened a device that is in use";
  } catch (const PtuLinkError& e) {
    EXPECT_EQ(e.kind(), PtuLinkErrorKind::Busy);
    EXPECT_NE(std::string(e.what()).find(rig.pty), std::string::npos) << e.what();
  }
}

TEST(PtuLink, PermissionDeniedIsNamed) {
  if (::geteuid() == 0) GTEST_SKIP() << "root opens any device";
  const std::string path = ::testing::TempDir() + "viewline_ptu_noperm";
  const int fd = ::open(path.c_str(), O_CREAT | O_WRONLY, 0000);
  ASSERT_GE(fd, 0);
  ::close(fd);
  try {
    SerialPtuLink link(path, 9600);
    FAIL() << "opened a device without permission";
  } catch (const PtuLinkError& e) {
    EXPECT_EQ(e.kind(), PtuLinkErrorKind::Permission) << e.what();
  }
  ::unlink(path.c_str());
}

TEST(PtuLink, RefusedTcpIsNamed) {
  int port = 0;
  {
    FlirPtuEmulator probe;
    port = probe.listenTcp(0);  // a free port, closed again when probe goes
  }
  try {
    TcpPtuLink link("127.0.0.1", port, 1.0);
    FAIL() << "connected to a closed port";
  } catch (const PtuLinkError& e) {
    EXPECT_EQ(e.kind(), PtuLinkErrorKind::Missing) << e.what();
    EXPECT_NE(std::string(e.what()).find("127.0.0.1:" + std::to_string(port)), std::string::npos) << e.what();
  }
}

TEST(PtuLink, ReadLineTimesOut) {
  Rig rig;
  SerialPtuLink link(rig.pty, 115200);
  const auto t0 = Clock::now();
  try {
    link.readLine(deadlineIn(0.1));
    FAIL() << "read a line nobody sent";
  } catch (const PtuLinkError& e) {
    EXPECT_EQ(e.kind(), PtuLinkErrorKind::Timeout);
  }
  const double waited = secondsSince(t0);
  EXPECT_GE(waited, 0.09);
  EXPECT_LT(waited, 0.5);
}

// --- driver against the emulator ---------------------------------------------------------------

TEST(FlirPtu, StartUpOverPty) {
  Rig rig;
  FlirPtu ptu(rig.serial());
  expectStartedUp(ptu, rig.emu);
  EXPECT_TRUE(rig.emu.velocityMode());
}

TEST(FlirPtu, StartUpOverTcp) {
  Rig rig;
  FlirPtu ptu(rig.tcp());
  expectStartedUp(ptu, rig.emu);
  EXPECT_TRUE(rig.emu.velocityMode());
}

TEST(FlirPtu, VelocityCommandMovesTheUnitAndReadsBack) {
  Rig rig;
  FlirPtu ptu(rig.tcp());
  const Eigen::Vector2d qdot(0.5, -0.25);  // rad/s
  const auto t0 = Clock::now();
  ptu.commandVelocity(0.0, qdot);
  sleepSeconds(0.4);
  const double t_read = secondsSince(t0);
  const JointState s = ptu.read(t_read);
  EXPECT_EQ(s.t, t_read);
  const Eigen::Vector2d res = ptu.resolution();
  // At speed (the ramp takes 0.5/20.9 = 24 ms), speeds read back to the position.
  EXPECT_NEAR(s.qdot(0), qdot(0), res(0));
  EXPECT_NEAR(s.qdot(1), qdot(1), res(1));
  // Travelled about qdot × elapsed (less the ramp), read back within the exchange's time.
  const double elapsed = s.t + ptu.lastRoundTrip();
  EXPECT_NEAR(s.q(0), qdot(0) * elapsed, 0.5 * 0.05 + 2 * res(0));
  EXPECT_NEAR(s.q(1), qdot(1) * elapsed, 0.25 * 0.05 + 2 * res(1));
  const JointState truth = rig.emu.state();
  EXPECT_NEAR(truth.q(0), s.q(0), 0.5 * 0.05);  // the emulator moved on since the read
  ptu.stop(secondsSince(t0));
  sleepSeconds(0.1);
  EXPECT_EQ(rig.emu.state().qdot.norm(), 0.0);
  EXPECT_GE(rig.emu.haltsReceived(), 1u);
}

TEST(FlirPtu, ASecondReadAtTheSameTimeCostsNoExchange) {
  Rig rig;
  FlirPtu ptu(rig.tcp());
  ptu.commandVelocity(0.0, Eigen::Vector2d(0.3, 0.0));
  sleepSeconds(0.05);
  const std::size_t sent = ptu.commandsSent();
  const JointState a = ptu.read(1.0);
  EXPECT_EQ(ptu.commandsSent(), sent + 4);
  sleepSeconds(0.05);
  const JointState b = ptu.read(1.0);  // the same sample: the unit is not asked again
  EXPECT_EQ(ptu.commandsSent(), sent + 4);
  EXPECT_EQ(a.q, b.q);
  const JointState c = ptu.read(1.1);  // a new time: a new sample, the unit has moved on
  EXPECT_EQ(ptu.commandsSent(), sent + 8);
  EXPECT_GT(c.q(0), a.q(0));
  ptu.commandVelocity(1.1, Eigen::Vector2d(0.3, 0.0));  // any exchange ends the sample's reuse
  ptu.read(1.1);
  EXPECT_EQ(ptu.commandsSent(), sent + 14);
}

TEST(FlirPtu, PositionModeMoveAndAwait) {
  Rig rig;
  FlirPtu ptu(rig.serial());
  ptu.moveTo(Eigen::Vector2d(0.3, -0.2), Eigen::Vector2d(2.0, 2.0));
  EXPECT_FALSE(ptu.velocityMode());
  EXPECT_FALSE(rig.emu.velocityMode());
  ptu.await(3.0);
  const JointState s = ptu.read(0.0);
  EXPECT_NEAR(s.q(0), 0.3, ptu.resolution()(0));
  EXPECT_NEAR(s.q(1), -0.2, ptu.resolution()(1));
  EXPECT_EQ(s.qdot.norm(), 0.0);
  // A velocity command switches back to pure velocity mode.
  ptu.commandVelocity(0.0, Eigen::Vector2d(0.1, 0.0));
  EXPECT_TRUE(rig.emu.velocityMode());
}

TEST(FlirPtu, PositionBeyondTheLimitIsALimitErrorAndHalts) {
  Rig rig;
  FlirPtu ptu(rig.tcp());
  const auto halts = rig.emu.haltsReceived();
  try {
    ptu.moveTo(Eigen::Vector2d(3.0, 0.0), Eigen::Vector2d(1.0, 1.0));
    FAIL() << "moved beyond the pan limit";
  } catch (const FlirPtuError& e) {
    EXPECT_EQ(e.kind(), FlirPtuErrorKind::Unit);
    EXPECT_EQ(e.unitError(), PtuErrorClass::PositionLimit);
    EXPECT_NE(std::string(e.what()).find("Maximum allowable Pan position exceeded"), std::string::npos) << e.what();
  }
  // The driver sends the halt after the error; the emulator's thread counts it when it has read it
  // (under load that can be after the throw returns here): wait for it, at most 1 s.
  for (int i = 0; i < 200 && rig.emu.haltsReceived() <= halts; ++i) sleepSeconds(0.005);
  EXPECT_GT(rig.emu.haltsReceived(), halts);
}

TEST(FlirPtu, DestructorHalts) {
  Rig rig;
  {
    FlirPtu ptu(rig.serial());
    ptu.commandVelocity(0.0, Eigen::Vector2d(0.4, 0.2));
    sleepSeconds(0.05);
  }
  sleepSeconds(0.1);
  EXPECT_GE(rig.emu.haltsReceived(), 1u);
  EXPECT_EQ(rig.emu.state().qdot.norm(), 0.0);
}

TEST(FlirPtu, VerboseEchoingUnitStartsUp) {
  // Power-up state: echo on and verbose; start-up must still parse every value.
  Rig rig;
  FlirPtu ptu(rig.serial());
  EXPECT_GT(ptu.limits().q_max(0), 2.6);
  const JointState s = ptu.read(0.0);
  EXPECT_EQ(s.q.norm(), 0.0);
}

// Every fault: a FlirPtuError of the expected kind, within a bounded time, after a halt.
struct FaultCase {
  PtuFault fault;
  FlirPtuErrorKind kind;
};

class FlirPtuFault : public ::testing::TestWithParam<std::tuple<FaultCase, bool>> {};

TEST_P(FlirPtuFault, GivesAClearErrorAndAHaltNeverAHang) {
  const auto [fc, use_tcp] = GetParam();
  Rig rig;
  const double timeout = 0.2;
  auto ptu = std::make_unique<FlirPtu>(use_tcp ? rig.tcp(timeout) : rig.serial(timeout));
  ptu->commandVelocity(0.0, Eigen::Vector2d(0.3, 0.1));
  const auto halts = rig.emu.haltsReceived();
  rig.emu.setReplyDelay(1.0);  // beyond the reply time-out
  rig.emu.setFault(fc.fault);
  sleepSeconds(0.02);  // the disconnect happens on the emulator's next tick
  const auto t0 = Clock::now();
  try {
    ptu->commandVelocity(0.1, Eigen::Vector2d(0.4, 0.1));
    ptu->read(0.1);
    FAIL() << "no error under the fault";
  } catch (const FlirPtuError& e) {
    EXPECT_EQ(e.kind(), fc.kind) << e.what();
    EXPECT_NE(std::string(e.what()).find(use_tcp ? "127.0.0.1:" : rig.pty), std::string::npos) << e.what();
    if (fc.fault == PtuFault::LimitError) {
      EXPECT_EQ(e.unitError(), PtuErrorClass::PositionLimit);
    }
  }
  // Bounded: the exchange's time-out plus the halt's (each <= 0.25 s) and the slow reply.
  EXPECT_LT(secondsSince(t0), 2.0);
  const auto t1 = Clock::now();
  ptu.reset();  // the destructor's halt is bounded too
  EXPECT_LT(secondsSince(t1), 1.5);
  if (fc.fault != PtuFault::Disconnect) {
    EXPECT_GT(rig.emu.haltsReceived(), halts) << "no halt reached the unit";
    sleepSeconds(0.05);
    EXPECT_EQ(rig.emu.state().qdot.norm(), 0.0);
  }
}

std::string faultCaseName(const ::testing::TestParamInfo<std::tuple<FaultCase, bool>>& param) {
  static const char* const kNames[] = {"None", "NoReply", "Garbled", "LimitError", "Disconnect", "Slow"};
  return std::string(kNames[static_cast<int>(std::get<0>(param.param).fault)]) + (std::get<1>(param.param) ? "Tcp" : "Pty");
}

INSTANTIATE_TEST_SUITE_P(AllFaults, FlirPtuFault,
                         ::testing::Combine(::testing::Values(FaultCase{PtuFault::NoReply, FlirPtuErrorKind::Timeout},
                                                              FaultCase{PtuFault::GarbledReply, FlirPtuErrorKind::Protocol},
                                                              FaultCase{PtuFault::LimitError, FlirPtuErrorKind::Unit},
                                                              FaultCase{PtuFault::Disconnect, FlirPtuErrorKind::Link},
                                                              FaultCase{PtuFault::SlowReply, FlirPtuErrorKind::Timeout}),
                                            ::testing::Bool()),
                         faultCaseName);

TEST(FlirPtu, SlowRepliesWithinTheTimeOutWork) {
  Rig rig;
  FlirPtu ptu(rig.tcp(0.5));
  rig.emu.setReplyDelay(0.05);
  rig.emu.setFault(PtuFault::SlowReply);
  ptu.commandVelocity(0.0, Eigen::Vector2d(0.1, 0.0));
  // Each reply leaves 50 ms after its command arrived; PS and TS arrive together.
  EXPECT_GE(ptu.lastRoundTrip(), 0.049);
  EXPECT_LT(ptu.lastRoundTrip(), 0.3);
}

TEST(FlirPtu, EmulatedBaudRateSetsTheExchangeTime) {
  Rig rig;
  FlirPtu ptu(rig.serial());
  rig.emu.setBaud(9600);
  ptu.read(0.0);  // "PP TP PD TD" in (3 bytes each), "* n\r\n" out (~7 bytes each): ~40 bytes, 42 ms
  EXPECT_GT(ptu.lastRoundTrip(), 0.030);
  EXPECT_LT(ptu.lastRoundTrip(), 0.150);
}

TEST(FlirPtu, StartUpAgainstNothingTimesOut) {
  // A pty nobody serves: the start-up's first reply never comes.
  FlirPtuEmulator silent;  // not started
  const std::string pty = silent.openPty();
  FlirPtuConfig c;
  c.port = pty;
  c.reply_timeout = 0.1;
  const auto t0 = Clock::now();
  try {
    FlirPtu ptu(c);
    FAIL() << "started up without a unit";
  } catch (const FlirPtuError& e) {
    EXPECT_EQ(e.kind(), FlirPtuErrorKind::Timeout);
    EXPECT_NE(std::string(e.what()).find("baud"), std::string::npos) << e.what();
  }
  EXPECT_LT(secondsSince(t0), 1.0);
}
