// CSV logs read back by viewline_tune's replays (tuning::detail::CsvTable in
// modules/tuning/src/adapter_util.h; e.g. predictive_frames.csv of pan_tilt_tracking --log, read by
// the pan-tilt adapter's readFrames). The input is the CSV file; it is read through a scratch file,
// then the columns readFrames needs are looked up and every field is read as a number, as the
// adapters do.

#include <string>

#include "adapter_util.h"
#include "fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  namespace detail = viewline::tuning::detail;
  const std::string text = viewline::fuzz::asText(data, size);
  detail::splitCsvLine(text);
  const std::string path = viewline::fuzz::scratchFile("predictive_frames.csv", text);
  // CsvTable has no column count accessor: its header is the first line, split the same way.
  const std::size_t columns = detail::splitCsvLine(text.substr(0, text.find('\n'))).size();
  viewline::fuzz::rejectOk([&] {
    const detail::CsvTable csv = detail::CsvTable::read(path, "predictive_frames.csv of pan_tilt_tracking --log");
    for (const char* c : {"t", "detected", "meas_x", "meas_y", "truth_x", "truth_y", "error_px"})
      viewline::fuzz::rejectOk([&] { csv.col(c); });
    for (std::size_t r = 0; r < csv.rows(); ++r) {
      csv.where(r);
      for (std::size_t c = 0; c < columns; ++c) {
        csv.text(r, c);
        viewline::fuzz::rejectOk([&] { csv.number(r, c); });
      }
    }
  });
  return 0;
}
