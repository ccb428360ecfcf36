// Replies of a FLIR pan-tilt unit as the driver reads them (robots::parsePtuReply in
// modules/robots/src/flir_ptu_protocol.cpp): the input is what arrives on the serial line or the
// TCP port, split into lines as PtuLink::readLine does ('\n', a '\r' before it dropped). Every
// line is parsed; the same bytes, split at the protocol's delimiters, are also fed to the
// emulator's command interpreter (robots::FlirPtuEmulator::process), which serves whatever a
// driver or a terminal sends it. PtuProtocolError and InvalidInput are the rejection paths.

#include <string>

#include "fuzz_util.h"
#include "viewline/robots/flir_ptu_protocol.h"
#include "viewline/robots/ptu_emulator.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  namespace robots = viewline::robots;
  const std::string text = viewline::fuzz::asText(data, size);
  std::size_t start = 0;
  while (start <= text.size()) {
    std::size_t nl = text.find('\n', start);
    if (nl == std::string::npos) nl = text.size();
    std::string line = text.substr(start, nl - start);
    if (!line.empty() && line.back() == '\r') line.pop_back();
    viewline::fuzz::rejectOk([&] {
      const robots::PtuReply r = robots::parsePtuReply(line);
      if (!r.ok) robots::toString(r.error);
    });
    robots::printableLine(line);
    start = nl + 1;
  }
  robots::FlirPtuEmulator emu;
  double t = 0.0;
  std::size_t from = 0;
  for (std::size_t k = 0; k <= text.size(); ++k) {
    if (k < text.size() && text[k] != ' ' && text[k] != '\r' && text[k] != '\n') continue;
    if (k > from) {
      t += 0.01;  // commands 10 ms apart: motion runs between them
      viewline::fuzz::rejectOk([&] { emu.process(std::string_view(text).substr(from, k - from), t); });
    }
    from = k + 1;
  }
  return 0;
}
