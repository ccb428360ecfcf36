#include "viewline/io/files.h"

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "viewline/core/error.h"
#include "viewline/core/interrupt.h"
#include "viewline/core/version.h"

namespace fs = std::filesystem;

namespace viewline::io {
namespace {

void makeParent(const std::string& path) {
  const fs::path parent = fs::path(path).parent_path();
  if (parent.empty()) return;
  std::error_code ec;
  fs::create_directories(parent, ec);
  if (ec) throw core::InvalidInput(path + ": cannot create directory " + parent.string() + ": " + ec.message());
}

std::string errnoText(int err) {
  std::string s = std::strerror(err);
  if (err == ENOSPC || err == EDQUOT) s += " (the disk is full)";
  if (err == EFBIG) s += " (over the file size limit)";
  return s;
}

const char* signalName(int sig) {
  switch (sig) {
    case SIGINT: return "SIGINT";
    case SIGTERM: return "SIGTERM";
    default: return "signal";
  }
}

}  // namespace

void throwFileError(const std::string& what, int err) {
  const std::string msg = what + ": " + errnoText(err);
  switch (err) {
    case ENOSPC: case EDQUOT: case EFBIG: case EIO: case EROFS:
      throw core::IoError(msg);
    default:
      throw core::InvalidInput(msg);
  }
}

std::string temporaryPathFor(const std::string& path) {
  static std::atomic<unsigned> counter{0};
  const fs::path p(path);
  const std::string name = "." + p.filename().string() + ".tmp" + std::to_string(::getpid()) + "_" +
                           std::to_string(counter++);
  return (p.parent_path() / name).string();
}

void writeAllOrThrow(int fd, const char* data, std::size_t size, const std::string& path) {
  while (size > 0) {
    const ssize_t n = ::write(fd, data, size);
    if (n < 0) {
      if (errno == EINTR) continue;  // a signal arrived mid-write: the write itself goes on
      throwFileError(path + ": cannot write", errno);
    }
    data += n;
    size -= static_cast<std::size_t>(n);
  }
}

void writeTextFileAtomic(const std::string& path, const std::string& content) {
  StagedFiles out;
  const std::string tmp = out.stage(path);
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (fd < 0) throwFileError(path + ": cannot open for writing", errno);
  try {
    writeAllOrThrow(fd, content.data(), content.size(), path);
    // fsync before the rename: after a power cut the target holds the old or the new content,
    // never a renamed but empty file (ext4's delayed allocation).
    if (::fsync(fd) != 0 && errno != EINVAL) throwFileError(path + ": cannot write", errno);
  } catch (...) {
    ::close(fd);
    throw;  // `out` removes the temporary; the target is untouched
  }
  if (::close(fd) != 0) throwFileError(path + ": cannot write", errno);
  out.commit();
}

void writeSummaryFile(const std::string& path, nlohmann::json j) {
  if (j.is_object()) {
    j["viewline_version"] = core::kVersion;
    // A run cut short by Ctrl-C / SIGTERM still writes its summary; it says so.
    if (const int sig = core::interruptSignal()) {
      j["interrupted"] = true;
      j["interrupt_signal"] = signalName(sig);
    }
  }
  writeJsonFile(path, j);
}

void writeJsonFile(const std::string& path, const nlohmann::json& j, int indent) {
  writeTextFileAtomic(path, j.dump(indent) + "\n");
}

nlohmann::json readJsonFile(const std::string& path) {
  std::ifstream f(path);
  if (!f) throw core::InvalidInput(path + ": cannot open JSON file");
  try {
    return nlohmann::json::parse(f);
  } catch (const nlohmann::json::parse_error& e) {
    throw core::InvalidInput(path + ": invalid JSON at byte " + std::to_string(e.byte) + ": " + e.what());
  }
}

StagedFiles::~StagedFiles() {
  if (!committed_) discard();
}

std::string StagedFiles::stage(const std::string& path) {
  if (path.empty()) throw core::InvalidInput("StagedFiles::stage: empty output path");
  for (const auto& f : files_)
    if (f.second == path) throw core::InvalidInput(path + ": output file named twice");
  makeParent(path);
  const std::string tmp = temporaryPathFor(path);
  std::error_code ec;
  fs::remove(tmp, ec);
  files_.emplace_back(tmp, path);
  committed_ = false;
  return tmp;
}

void StagedFiles::commit() {
  for (const auto& f : files_)
    if (!fs::exists(f.first)) {
      const std::string target = f.second;  // discard() clears files_, which f points into (ASan: use after free)
      discard();
      throw core::InvalidInput(target + ": the file was not written");
    }
  for (const auto& f : files_) {
    std::error_code ec;
    fs::rename(f.first, f.second, ec);
    if (ec) {
      const std::string target = f.second;  // (as above)
      discard();
      throwFileError(target + ": cannot rename the temporary file onto it", ec.value());
    }
  }
  files_.clear();
  committed_ = true;
}

void StagedFiles::discard() {
  for (const auto& f : files_) {
    std::error_code ec;
    fs::remove(f.first, ec);
  }
  files_.clear();
}

std::vector<std::string> StagedFiles::targets() const {
  std::vector<std::string> out;
  for (const auto& f : files_) out.push_back(f.second);
  return out;
}

}  // namespace viewline::io
