#include "viewline/io/files.h"

#include <atomic>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <unistd.h>

#include "viewline/core/error.h"

namespace fs = std::filesystem;

namespace viewline::io {
namespace {

std::string tmpPathFor(const std::string& path) {
  static std::atomic<unsigned> counter{0};
  const fs::path p(path);
  const std::string name = "." + p.filename().string() + ".tmp" + std::to_string(::getpid()) + "_" +
                           std::to_string(counter++);
  return (p.parent_path() / name).string();
}

void makeParent(const std::string& path) {
  const fs::path parent = fs::path(path).parent_path();
  if (parent.empty()) return;
  std::error_code ec;
  fs::create_directories(parent, ec);
  if (ec) throw core::InvalidInput(path + ": cannot create directory " + parent.string() + ": " + ec.message());
}

}  // namespace

void writeTextFileAtomic(const std::string& path, const std::string& content) {
  StagedFiles out;
  const std::string tmp = out.stage(path);
  {
    std::ofstream f(tmp, std::ios::binary);
    if (!f) throw core::InvalidInput(path + ": cannot open for writing");
    f << content;
    f.flush();
    if (!f) throw core::InvalidInput(path + ": write failed");
  }
  out.commit();
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
  const std::string tmp = tmpPathFor(path);
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
      throw core::InvalidInput(target + ": cannot rename the temporary file onto it: " + ec.message());
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
