#include "viewline/io/log.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>

#include "viewline/core/error.h"
#include "viewline/io/files.h"

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
  tmp_ = temporaryPathFor(path);
  fd_ = ::open(tmp_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd_ < 0)
    throwFileError(path + ": cannot open the CSV log for writing", errno);
  std::string line;
  for (std::size_t i = 0; i < header_.size(); ++i) line += (i ? "," : "") + quote(header_[i]);
  append(line);
}

CsvWriter::~CsvWriter() {
  try {
    close();
  } catch (const std::exception& e) {
    std::cerr << e.what() << "\n";  // a destructor must not throw; the message still names the file
  }
  if (fd_ >= 0) ::close(fd_);
  if (!tmp_.empty()) {
    std::error_code ec;
    std::filesystem::remove(tmp_, ec);  // never published (the write failed): no stray temporary
  }
}

void CsvWriter::append(const std::string& line) {
  buffer_ += line;
  buffer_ += '\n';
  if (buffer_.size() >= (1u << 16)) writeBuffer();  // whole lines in 64 KB writes
}

void CsvWriter::writeBuffer() {
  const std::string data = std::move(buffer_);
  buffer_.clear();
  try {
    writeAllOrThrow(fd_, data.data(), data.size(), path_);
  } catch (...) {
    // A failed write (disk full) ends the log: the writer is disabled and an unpublished temporary
    // removed, so no truncated file appears under the log's name.
    ::close(fd_);
    fd_ = -1;
    if (!tmp_.empty()) {
      std::error_code ec;
      std::filesystem::remove(tmp_, ec);
      tmp_.clear();
    }
    throw;
  }
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
  append(line);
  ++rows_;
}

void CsvWriter::rowText(const std::vector<std::string>& fields) {
  if (!enabled()) return;
  checkCount(fields.size());
  std::string line;
  for (std::size_t i = 0; i < fields.size(); ++i) line += (i ? "," : "") + quote(fields[i]);
  append(line);
  ++rows_;
}

void CsvWriter::flush() {
  if (!enabled()) return;
  writeBuffer();
  if (!tmp_.empty()) {
    // The open descriptor follows the rename: later rows are appended to the published file.
    std::error_code ec;
    std::filesystem::rename(tmp_, path_, ec);
    if (ec) throwFileError(path_ + ": cannot rename the temporary CSV log onto it", ec.value());
    tmp_.clear();
  }
}

void CsvWriter::close() {
  if (!enabled()) return;
  flush();
  const int fd = fd_;
  fd_ = -1;
  if (::close(fd) != 0) throwFileError(path_ + ": cannot write", errno);
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
