// Stamps files beside image sequences and videos (runtime::parseStamps, modules/runtime/stamps.h):
// `index,stamp` lines, a header, comments. The input is the file's text.

#include <string>

#include "fuzz_util.h"
#include "viewline/runtime/stamps.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text = viewline::fuzz::asText(data, size);
  viewline::fuzz::rejectOk([&] {
    const auto stamps = viewline::runtime::parseStamps(text, "stamps.csv");
    // What the parser promises its users: strictly increasing indices and finite stamps.
    for (std::size_t i = 1; i < stamps.size(); ++i)
      if (!(stamps[i].index > stamps[i - 1].index && stamps[i].stamp > stamps[i - 1].stamp)) __builtin_trap();
  });
  viewline::fuzz::rejectOk([&] { viewline::runtime::csv::splitLine(text); });
  return 0;
}
