#pragma once
// CSV logs (--log DIR): one file per stream (truth, measurements, estimates...),
// a header line, then one row per sample.
//
//   io::LogDirectory log(cli_log_dir);            // "" = logging off, every call a no-op
//   auto& est = log.stream("estimates", {"t", "x", "y", "z"});
//   est.row({t, x(0), x(1), x(2)});               // column count checked against the header
//   log.flush();                                  // end of the run: every file complete, errors thrown
//
// Nothing half-written replaces a file: rows go to a temporary file next to `<name>.csv`, which is
// renamed onto it at the first flush() (or when the writer closes, also when a run is interrupted
// or fails); later rows are appended in whole lines. Write errors (a full disk) throw
// core::InvalidInput naming the file.

#include <map>
#include <memory>
#include <string>
#include <vector>

namespace viewline::io {

/// One CSV file: header line, then rows of numbers or text; disabled writers discard rows.
class CsvWriter {
public:
  /// A disabled writer: rows are discarded.
  CsvWriter() = default;
  /// Opens a temporary file next to `path` and writes the header. Throws InvalidInput naming the path.
  CsvWriter(const std::string& path, std::vector<std::string> header, int precision = 12);
  /// Closes the file, renaming the temporary onto `path` if flush() never did (errors are printed
  /// to stderr, not thrown: call close() to see them).
  ~CsvWriter();
  /// Not copyable: one writer owns its file.
  CsvWriter(const CsvWriter&) = delete;
  /// Not copyable: one writer owns its file.
  CsvWriter& operator=(const CsvWriter&) = delete;

  /// Whether rows are written (false for the disabled writer).
  bool enabled() const { return fd_ >= 0; }
  /// Column names, as written in the header line.
  const std::vector<std::string>& header() const { return header_; }
  /// Path of the CSV file ("" when disabled).
  const std::string& path() const { return path_; }
  /// Number of rows written so far.
  std::size_t rows() const { return rows_; }

  /// Numbers (NaN is written as "nan": a missing value). Throws when the count differs from the header.
  void row(const std::vector<double>& values);
  /// Text fields (quoted when they contain a comma, quote or newline).
  void rowText(const std::vector<std::string>& fields);
  /// Writes the buffered rows and makes the file visible at path() (renames the temporary onto it
  /// the first time). Throws InvalidInput naming the file when the system refuses (disk full).
  void flush();
  /// flush(), then closes the file; later rows are discarded. Idempotent.
  void close();

private:
  void checkCount(std::size_t n) const;
  void append(const std::string& line);
  void writeBuffer();
  std::string path_;
  std::string tmp_;            // the temporary until published, then empty
  std::vector<std::string> header_;
  int fd_ = -1;
  std::string buffer_;         // whole lines not yet written
  int precision_ = 12;
  std::size_t rows_ = 0;
};

/// The folder of a run's CSV logs (--log DIR): one CsvWriter per stream, all no-ops when disabled.
class LogDirectory {
public:
  /// `dir` empty: disabled. Otherwise the directory is created when missing.
  explicit LogDirectory(const std::string& dir = {});
  /// True when logging to a folder.
  bool enabled() const { return !dir_.empty(); }
  /// The log folder ("" when disabled).
  const std::string& dir() const { return dir_; }
  /// The writer of `<dir>/<name>.csv`, created on first use. Asking again with a different
  /// header throws. When disabled, a shared no-op writer. `precision`: significant digits (17: every
  /// double reads back exactly, for logs that are replayed).
  CsvWriter& stream(const std::string& name, const std::vector<std::string>& header, int precision = 12);
  /// Flushes every stream (each file complete at its path); throws naming the first file that fails.
  void flush();

private:
  std::string dir_;
  std::map<std::string, std::unique_ptr<CsvWriter>> streams_;
  CsvWriter null_;
};

}  // namespace viewline::io
