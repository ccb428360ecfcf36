#pragma once
// CSV logs (--log DIR): one file per stream (truth, measurements, estimates...),
// a header line, then one row per sample.
//
//   io::LogDirectory log(cli_log_dir);            // "" = logging off, every call a no-op
//   auto& est = log.stream("estimates", {"t", "x", "y", "z"});
//   est.row({t, x(0), x(1), x(2)});               // column count checked against the header

#include <fstream>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace viewline::io {

class CsvWriter {
public:
  /// A disabled writer: rows are discarded.
  CsvWriter() = default;
  /// Creates (truncates) `path` and writes the header. Throws InvalidInput naming the path.
  CsvWriter(const std::string& path, std::vector<std::string> header, int precision = 12);

  bool enabled() const { return out_.is_open(); }
  const std::vector<std::string>& header() const { return header_; }
  const std::string& path() const { return path_; }
  std::size_t rows() const { return rows_; }

  /// Numbers (NaN is written as "nan": a missing value). Throws when the count differs from the header.
  void row(const std::vector<double>& values);
  /// Text fields (quoted when they contain a comma, quote or newline).
  void rowText(const std::vector<std::string>& fields);
  void flush();

private:
  void checkCount(std::size_t n) const;
  std::string path_;
  std::vector<std::string> header_;
  std::ofstream out_;
  int precision_ = 12;
  std::size_t rows_ = 0;
};

class LogDirectory {
public:
  /// `dir` empty: disabled. Otherwise the directory is created when missing.
  explicit LogDirectory(const std::string& dir = {});
  bool enabled() const { return !dir_.empty(); }
  const std::string& dir() const { return dir_; }
  /// The writer of `<dir>/<name>.csv`, created on first use. Asking again with a different
  /// header throws. When disabled, a shared no-op writer. `precision`: significant digits (17: every
  /// double reads back exactly, for logs that are replayed).
  CsvWriter& stream(const std::string& name, const std::vector<std::string>& header, int precision = 12);
  void flush();

private:
  std::string dir_;
  std::map<std::string, std::unique_ptr<CsvWriter>> streams_;
  CsvWriter null_;
};

}  // namespace viewline::io
