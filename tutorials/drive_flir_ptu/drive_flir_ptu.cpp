// drive_flir_ptu: the FLIR PTU driver (robots::FlirPtu) in 80 lines, for tutorials/drive_flir_ptu.
//
//   drive_flir_ptu --tcp 127.0.0.1:4000          # an E-series unit or viewline_ptu_emulator --tcp
//   drive_flir_ptu --port /dev/ttyUSB0 [BAUD]    # a serial unit (default 9600 baud) or the emulator's pty
#include <chrono>
#include <cstdio>
#include <string>
#include <thread>

#include "viewline/robots/flir_ptu.h"

using namespace viewline;

namespace {
double deg(double rad) { return rad * 180.0 / M_PI; }
void sleepSeconds(double s) { std::this_thread::sleep_for(std::chrono::duration<double>(s)); }
}  // namespace

int main(int argc, char** argv) {
  const std::string how = argc >= 3 ? argv[1] : "";
  if (how != "--tcp" && how != "--port") {
    std::fprintf(stderr, "usage: drive_flir_ptu --tcp HOST:PORT | --port DEVICE [BAUD]\n");
    return 2;
  }
  robots::FlirPtuConfig config;
  (how == "--tcp" ? config.tcp : config.port) = argv[2];
  if (argc >= 4) config.baud = std::stoi(argv[3]);
  try {
    robots::FlirPtu ptu(config);  // echo off, terse feedback, resolution and limits, velocity mode
    const robots::PanTiltLimits& l = ptu.limits();
    std::printf("%s\n", ptu.name().c_str());
    std::printf("resolution: pan %.6f deg, tilt %.6f deg per position\n", deg(ptu.resolution()(0)), deg(ptu.resolution()(1)));
    std::printf("limits: pan %.2f..%.2f deg, tilt %.2f..%.2f deg, speed %.1f deg/s, acceleration %.0f deg/s^2\n",
                deg(l.q_min(0)), deg(l.q_max(0)), deg(l.q_min(1)), deg(l.q_max(1)), deg(l.qdot_max(0)), deg(l.qddot_max(0)));

    // Position mode: go to (0.3, -0.2) rad at 1 rad/s, wait until there (A), read back.
    ptu.moveTo(Eigen::Vector2d(0.3, -0.2), Eigen::Vector2d(1.0, 1.0));
    ptu.await(5.0);
    robots::JointState s = ptu.read(0.0);
    std::printf("after the move: pan %.4f rad, tilt %.4f rad\n", s.q(0), s.q(1));

    // Pure velocity mode (what a visual-servo loop sends): pan at 0.2 rad/s for half a second.
    ptu.commandVelocity(0.0, Eigen::Vector2d(0.2, 0.0));
    sleepSeconds(0.5);
    s = ptu.read(0.5);
    std::printf("moving: pan speed %.4f rad/s, pan %.3f rad\n", s.qdot(0), s.q(0));
    ptu.stop(0.5);  // H: both axes decelerate to rest
    sleepSeconds(0.1);
    s = ptu.read(0.6);
    std::printf("halted: pan speed %.4f rad/s\n", s.qdot(0));
    std::printf("%zu commands, last exchange %.2f ms\n", ptu.commandsSent(), 1e3 * ptu.lastRoundTrip());
    return 0;
  } catch (const robots::FlirPtuError& e) {  // the unit was sent a halt before this was thrown
    std::fprintf(stderr, "drive_flir_ptu: %s\n", e.what());
    return 1;
  } catch (const core::Error& e) {
    std::fprintf(stderr, "drive_flir_ptu: %s\n", e.what());
    return 1;
  }
}
