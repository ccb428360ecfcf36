// viewline_ptu_emulator: serves the FLIR PTU ASCII protocol (robots::FlirPtuEmulator) so that the
// driver (robots::FlirPtu), the pan-tilt app with `robot: {kind: flir_ptu, ...}` or a terminal can
// talk to a pan-tilt unit without one. Prints where it listens, then runs until SIGINT/SIGTERM
// (or --duration), and prints what it served.
//
//   viewline_ptu_emulator --pty --tcp 4000             # both; prints "pty: /dev/pts/N", "tcp: 127.0.0.1:4000"
//   viewline_ptu_emulator --tcp 0 --endpoints FILE     # any free port, written to FILE when ready
//   viewline_ptu_emulator --pty --baud 9600 --fault slow --reply-delay 0.2
//   viewline_ptu_emulator --tcp 0 --fault no_reply --fault-after 2   # behaves for 2 s, then stops answering
#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <thread>

#include "app_options.h"
#include "viewline/core/interrupt.h"
#include "viewline/core/version.h"
#include "viewline/robots/ptu_emulator.h"

using namespace viewline;

int main(int argc, char** argv) {
  CLI::App cli{"viewline_ptu_emulator: an emulated FLIR PTU-D46 (ASCII protocol) on a pty and/or a TCP port"};
  cli.set_version_flag("--version", std::string("viewline ") + core::kVersion);
  bool pty = false;
  int tcp = -1;
  int baud = 0;
  std::string fault = "none";
  double reply_delay = 0.0, drive_latency = 0.0, duration = 0.0, fault_after = 0.0;
  std::string endpoints;
  cli.add_flag("--pty", pty, "serve on a pseudo-terminal (its path is printed: pass it as the serial port)");
  cli.add_option("--tcp", tcp, "serve on 127.0.0.1:PORT (0: any free port; the port is printed)")->check(CLI::Range(0, 65535));
  cli.add_option("--baud", baud, "emulated line rate, bit/s (10 bit times per byte in and out; 0: none)")->check(CLI::NonNegativeNumber);
  cli.add_option("--fault", fault, "none, no_reply, garbled, limit_error, disconnect or slow");
  cli.add_option("--fault-after", fault_after, "s of good behaviour before --fault switches on (0: from the start)")
      ->check(CLI::NonNegativeNumber);
  cli.add_option("--reply-delay", reply_delay, "s before each reply under --fault slow")->check(CLI::NonNegativeNumber);
  cli.add_option("--drive-latency", drive_latency, "s between a command's arrival and its effect")->check(CLI::NonNegativeNumber);
  cli.add_option("--duration", duration, "s to run (0: until SIGINT/SIGTERM)")->check(CLI::NonNegativeNumber);
  cli.add_option("--endpoints", endpoints, "write 'pty: PATH' / 'tcp: HOST:PORT' lines to this file once serving");
  if (const auto code = apps::parseCommandLine(cli, argc, argv)) return *code;
  if (!pty && tcp < 0) {
    std::fprintf(stderr, "viewline_ptu_emulator: nothing to serve on: give --pty and/or --tcp PORT\n");
    return 2;
  }
  // The stop signal ends the serving loop below, which then reports; not an interrupted run.
  return apps::runGuarded("viewline_ptu_emulator", [&] {
    robots::PtuEmulatorParams params;
    params.drive_latency = drive_latency;
    robots::FlirPtuEmulator emu(params);
    const robots::PtuFault the_fault = robots::parsePtuFault(fault);
    if (fault_after <= 0.0) emu.setFault(the_fault);
    emu.setReplyDelay(reply_delay);
    emu.setBaud(baud);
    std::string lines;
    if (pty) lines += "pty: " + emu.openPty() + "\n";
    if (tcp >= 0) lines += "tcp: 127.0.0.1:" + std::to_string(emu.listenTcp(tcp)) + "\n";
    emu.start();
    std::fputs(lines.c_str(), stdout);
    std::fflush(stdout);
    if (!endpoints.empty()) {
      const std::string tmp = endpoints + ".tmp";
      std::ofstream(tmp) << lines;
      std::rename(tmp.c_str(), endpoints.c_str());  // readers never see half a file
    }
    const auto t0 = std::chrono::steady_clock::now();
    const auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(); };
    bool faulty = fault_after <= 0.0;
    while (!core::interruptRequested() && (duration <= 0.0 || elapsed() < duration)) {
      if (!faulty && elapsed() >= fault_after) {
        emu.setFault(the_fault);
        faulty = true;
        std::printf("fault %s on after %.1f s\n", fault.c_str(), fault_after);
        std::fflush(stdout);
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    emu.stop();
    const robots::JointState s = emu.state();
    std::printf("served %llu commands (%llu halts); final joints pan %.4f rad, tilt %.4f rad\n",
                static_cast<unsigned long long>(emu.commandsHandled()), static_cast<unsigned long long>(emu.haltsReceived()),
                s.q(0), s.q(1));
    core::clearInterrupt();
    return 0;
  });
}
