#pragma once
// Shared pieces of the fuzz targets (fuzz/README.md).
//
//  - Every target defines LLVMFuzzerTestOneInput; with -DVIEWLINE_BUILD_FUZZ=ON (clang) libFuzzer
//    drives it, otherwise replay_main.cpp replays the committed corpus through it (ctest label fuzz).
//  - core::Error (InvalidInput, NumericalError) is the documented rejection path of every parser and
//    is caught by the targets; any other exception escapes, and libFuzzer reports it as a crash.
//  - Parsers that only take a path get the input through a file in a directory unique to the
//    process (scratchFile, under /dev/shm when present), removed at exit.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>

#include "viewline/core/error.h"

namespace viewline::fuzz {

class ScratchDir {
public:
  ScratchDir() {
    // tmpfs when there is one: a file is written per execution.
    const std::filesystem::path base =
        std::filesystem::is_directory("/dev/shm") ? std::filesystem::path("/dev/shm") : std::filesystem::temp_directory_path();
    dir_ = base / ("viewline_fuzz_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir_);
  }
  ~ScratchDir() {
    std::error_code ec;
    std::filesystem::remove_all(dir_, ec);
  }
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;
  const std::filesystem::path& dir() const { return dir_; }

private:
  std::filesystem::path dir_;
};

/// Writes `text` to `<scratch dir>/<name>` (replacing it) and returns the path.
inline std::string scratchFile(const std::string& name, const std::string& text) {
  static ScratchDir scratch;
  const std::string path = (scratch.dir() / name).string();
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(text.data(), static_cast<std::streamsize>(text.size()));
  return path;
}

inline std::string asText(const std::uint8_t* data, std::size_t size) {
  return std::string(reinterpret_cast<const char*>(data), size);
}

/// Runs `f`, swallowing the documented rejection (core::Error and its subclasses).
template <class F>
void rejectOk(F&& f) {
  try {
    f();
  } catch (const core::Error&) {
  }
}

}  // namespace viewline::fuzz
