#pragma once
// Time stamps of recorded frames, from a small CSV file beside an image sequence or a video
// (one line per frame: `index,stamp`, stamp in seconds on the recording's clock). Lines starting
// with '#' and blank lines are skipped; a first line `index,stamp` is taken as the header.
//
// A stamps file is user input: every defect (a non-numeric or non-finite field, a missing or
// extra column, an index or stamp that does not increase) is a core::InvalidInput whose message
// starts with "<file>:<line>:" and says what was expected, never a silently wrong clock. The
// parsing helpers are shared with the recording index (recording.h).

#include <cstdint>
#include <string>
#include <vector>

namespace viewline::runtime {

/// One line of a stamps file: the frame's index (as in the image file pattern or the video's
/// frame order, from 0) and its time stamp, s.
struct StampEntry {
  std::int64_t index = 0;  ///< frame index (image pattern number, or video frame number from 0)
  double stamp = 0.0;      ///< capture time stamp, s
};

/// Parses the text of a stamps file; `file` names it in the messages. Throws core::InvalidInput
/// "<file>:<line>: ..." on a malformed line or when index or stamp does not strictly increase.
std::vector<StampEntry> parseStamps(const std::string& text, const std::string& file);
/// Reads and parses a stamps file (parseStamps); a missing or unreadable file is named.
std::vector<StampEntry> readStampsFile(const std::string& path);

namespace csv {

/// Splits one CSV line at commas (no quoting: our files never quote); trailing '\r' removed.
std::vector<std::string> splitLine(const std::string& line);
/// A finite double in the whole field (leading/trailing blanks allowed), else InvalidInput
/// "<file>:<line>: <column>: expected a number, got '<field>'".
double parseDouble(const std::string& field, const std::string& column, const std::string& file, std::size_t line);
/// A whole integer in the whole field, else InvalidInput naming file, line and column.
std::int64_t parseInt(const std::string& field, const std::string& column, const std::string& file, std::size_t line);
/// The whole text of a file; InvalidInput naming the file when it is missing or unreadable.
std::string readWholeFile(const std::string& path, const std::string& what);

}  // namespace csv

}  // namespace viewline::runtime
