#pragma once
// Writing output files so that a crash or an error never leaves a half-written
// file: content goes to a temporary file next to the target, which is renamed
// over the target (rename is atomic on POSIX within one file system).

#include <cstddef>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace viewline::io {

/// Writes `content` to `path` atomically (tmp file + fsync + rename). Creates missing parent
/// directories. Throws core::InvalidInput naming the path and the cause (e.g. "No space left on
/// device (the disk is full)") on failure; the target is then untouched and no temporary is left.
void writeTextFileAtomic(const std::string& path, const std::string& content);

/// nlohmann::json to a file, atomically (e.g. an app's --summary FILE).
void writeJsonFile(const std::string& path, const nlohmann::json& j, int indent = 2);
/// An app's --summary FILE: `j` with "viewline_version" (core::kVersion) added, written atomically,
/// so every summary says which version produced it. After a SIGINT/SIGTERM (core::interruptRequested())
/// it also gets `"interrupted": true` and `"interrupt_signal"` ("SIGINT" or "SIGTERM"): a partial run.
void writeSummaryFile(const std::string& path, nlohmann::json j);
/// Reads a JSON file; errors name the file and the parse position.
nlohmann::json readJsonFile(const std::string& path);

/// A fresh name for a temporary file next to `path` (same folder, so a rename onto `path` is atomic):
/// ".<name>.tmp<pid>_<n>", hidden, unique within the process.
std::string temporaryPathFor(const std::string& path);
/// Throws the error for a failed file operation with errno `err`, the message `what: <cause>`:
/// core::IoError when the system refused (ENOSPC/EDQUOT "the disk is full", EFBIG, EIO, EROFS),
/// core::InvalidInput when the path cannot be used as given (missing folder, not a folder,
/// permission).
[[noreturn]] void throwFileError(const std::string& what, int err);
/// write(2) of all `size` bytes to `fd` (retried after EINTR); throws (throwFileError) naming
/// `path` and the cause (disk full, file size limit...) when the system refuses.
void writeAllOrThrow(int fd, const char* data, std::size_t size, const std::string& path);

/// All-or-nothing output of several files, whoever writes them (ofstream, cv::FileStorage,
/// vpXmlParserCamera...):
///
///   io::StagedFiles out;
///   writeSomething(out.stage("a.xml"));   // returns a temporary path next to a.xml
///   writeOther(out.stage("b.yaml"));
///   out.commit();                         // renames all; until then no target is touched
///
/// If commit() is never reached (an exception), the destructor deletes the temporaries.
class StagedFiles {
public:
  StagedFiles() = default;
  StagedFiles(const StagedFiles&) = delete;
  StagedFiles& operator=(const StagedFiles&) = delete;
  ~StagedFiles();

  /// A fresh temporary path (not existing) for the final `path`; creates parent directories.
  std::string stage(const std::string& path);
  /// Checks every temporary exists, then renames them onto their targets.
  void commit();
  /// Deletes all temporaries (also done by the destructor when not committed).
  void discard();
  /// Final paths staged so far.
  std::vector<std::string> targets() const;

private:
  std::vector<std::pair<std::string, std::string>> files_;  // (tmp, final)
  bool committed_ = false;
};

}  // namespace viewline::io
