#include "viewline/io/log.h"

#include <cmath>
#include <cstdio>
#include <filesystem>

#include "viewline/core/error.h"

namespace viewline::io {
namespace {
std::string quote(const std::string& s) {
  if (s.find_first_of(",\"\n\r") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) {
    if (c == '"') q += '"';
    q += c;
  }
  return q + "\"";
}
}  // namespace

CsvWriter::CsvWriter(const std::string& path, std::vector<std::string> header, int precision)
    : path_(path), header_(std::move(header)), precision_(precision) {
  if (header_.empty()) throw core::InvalidInput(path + ": a CSV log needs at least one column");
  if (precision_ < 1 || precision_ > 17) throw core::InvalidInput(path + ": CSV precision must be in 1..17");
  const auto parent = std::filesystem::path(path).parent_path();
  if (!parent.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(parent, ec);
  }
  out_.open(path, std::ios::trunc);
  if (!out_) throw core::InvalidInput(path + ": cannot open the CSV log for writing");
  std::string line;
  for (std::size_t i = 0; i < header_.size(); ++i) line += (i ? "," : "") + quote(header_[i]);
  out_ << line << '\n';
}

void CsvWriter::checkCount(std::size_t n) const {
  if (n != header_.size())
    throw core::InvalidInput(path_ + ": CSV row has " + std::to_string(n) + " values, expected " +
                             std::to_string(header_.size()) + " (the header's columns)");
}

void CsvWriter::row(const std::vector<double>& values) {
  if (!enabled()) return;
  checkCount(values.size());
  std::string line;
  char buf[64];
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (i) line += ',';
    if (std::isnan(values[i])) {
      line += "nan";
    } else {
      std::snprintf(buf, sizeof buf, "%.*g", precision_, values[i]);
      line += buf;
    }
  }
  out_ << line << '\n';
  ++rows_;
}

void CsvWriter::rowText(const std::vector<std::string>& fields) {
  if (!enabled()) return;
  checkCount(fields.size());
  std::string line;
  for (std::size_t i = 0; i < fields.size(); ++i) line += (i ? "," : "") + quote(fields[i]);
  out_ << line << '\n';
  ++rows_;
}

void CsvWriter::flush() {
  if (enabled()) out_.flush();
}

LogDirectory::LogDirectory(const std::string& dir) : dir_(dir) {
  if (dir_.empty()) return;
  std::error_code ec;
  std::filesystem::create_directories(dir_, ec);
  if (ec || !std::filesystem::is_directory(dir_))
    throw core::InvalidInput(dir_ + ": cannot create the log directory" + (ec ? ": " + ec.message() : ""));
}

CsvWriter& LogDirectory::stream(const std::string& name, const std::vector<std::string>& header, int precision) {
  if (!enabled()) return null_;
  if (name.empty() || name.find('/') != std::string::npos)
    throw core::InvalidInput("log stream name '" + name + "': expected a plain file stem");
  auto it = streams_.find(name);
  if (it != streams_.end()) {
    if (it->second->header() != header)
      throw core::InvalidInput(it->second->path() + ": log stream reopened with a different header");
    return *it->second;
  }
  const std::string path = (std::filesystem::path(dir_) / (name + ".csv")).string();
  auto w = std::make_unique<CsvWriter>(path, header, precision);
  CsvWriter& ref = *w;
  streams_.emplace(name, std::move(w));
  return ref;
}

void LogDirectory::flush() {
  for (auto& s : streams_) s.second->flush();
}

}  // namespace viewline::io
