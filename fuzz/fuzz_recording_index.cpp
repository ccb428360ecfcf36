// viewline recordings (modules/runtime/recording.h): the index recording.csv
// (runtime::parseRecordingIndex) and truth.csv (runtime::parseRecordingTruth). The input is the
// text of either file; both parsers read it.

#include <string>

#include "fuzz_util.h"
#include "viewline/runtime/recording.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text = viewline::fuzz::asText(data, size);
  viewline::fuzz::rejectOk([&] {
    const auto rows = viewline::runtime::parseRecordingIndex(text, "recording.csv");
    // What RecordingSource relies on: ready times in order, image paths inside the folder.
    for (std::size_t i = 0; i < rows.size(); ++i) {
      if (i > 0 && rows[i].ready_time < rows[i - 1].ready_time) __builtin_trap();
      if (!rows[i].file.empty() && (rows[i].file.front() == '/' || rows[i].file.find("..") != std::string::npos))
        __builtin_trap();
    }
  });
  viewline::fuzz::rejectOk([&] { viewline::runtime::parseRecordingTruth(text, "truth.csv"); });
  return 0;
}
