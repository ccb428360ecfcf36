#include <gtest/gtest.h>
#include <sys/resource.h>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "temp_dir.h"
#include "viewline/core/error.h"
#include "viewline/core/interrupt.h"
#include "viewline/io/files.h"
#include "viewline/io/log.h"

using namespace viewline::io;
using viewline::core::InvalidInput;
using viewline::core::IoError;
using viewline::io::test::TempDir;

namespace {
std::string slurp(const std::string& p) {
  std::ifstream f(p);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}
}  // namespace

TEST(Files, JsonSummaryIsWrittenAtomicallyAndReadsBack) {
  TempDir dir;
  const auto path = dir.file("sub/summary.json");
  nlohmann::json j;
  j["rmse_m"] = 0.0123;
  j["catches"] = 7;
  writeJsonFile(path, j);
  EXPECT_EQ(readJsonFile(path), j);
  // Overwrite keeps exactly one file (no temporaries left).
  j["catches"] = 8;
  writeJsonFile(path, j);
  EXPECT_EQ(readJsonFile(path)["catches"], 8);
  std::size_t n = 0;
  for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(dir.path / "sub")) ++n;
  EXPECT_EQ(n, 1u);
}

TEST(Files, BadJsonNamesFile) {
  TempDir dir;
  const auto p = dir.write("b.json", "{\"a\": ");
  try {
    readJsonFile(p);
    FAIL();
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find(p), std::string::npos);
  }
}

TEST(Files, StagedFilesAreAllOrNothing) {
  TempDir dir;
  {
    StagedFiles out;
    std::ofstream(out.stage(dir.file("a.txt"))) << "a";
    std::ofstream(out.stage(dir.file("b.txt"))) << "b";
    EXPECT_EQ(dir.count(), 2u);  // temporaries only
    EXPECT_FALSE(std::filesystem::exists(dir.file("a.txt")));
    // no commit: destructor removes the temporaries
  }
  EXPECT_EQ(dir.count(), 0u);
  {
    StagedFiles out;
    std::ofstream(out.stage(dir.file("a.txt"))) << "a";
    out.stage(dir.file("b.txt"));  // never written: commit must fail and leave nothing
    EXPECT_THROW(out.commit(), InvalidInput);
  }
  EXPECT_EQ(dir.count(), 0u);
  StagedFiles out;
  std::ofstream(out.stage(dir.file("a.txt"))) << "a";
  out.commit();
  EXPECT_EQ(slurp(dir.file("a.txt")), "a");
  EXPECT_EQ(dir.count(), 1u);
}

TEST(Log, CsvStreamsOnePerFileWithHeader) {
  TempDir dir;
  {
    LogDirectory log(dir.file("log"));
    auto& est = log.stream("estimates", {"t", "x", "note"});
    est.row({0.5, 1.25, std::nan("")});
    est.rowText({"1", "2", "a,b"});
    EXPECT_THROW(est.row({1.0, 2.0}), InvalidInput);
    EXPECT_EQ(&log.stream("estimates", {"t", "x", "note"}), &est);
    EXPECT_THROW(log.stream("estimates", {"t"}), InvalidInput);
    log.stream("truth", {"t"}).row({0.0});
  }
  EXPECT_EQ(slurp(dir.file("log/estimates.csv")), "t,x,note\n0.5,1.25,nan\n1,2,\"a,b\"\n");
  EXPECT_EQ(slurp(dir.file("log/truth.csv")), "t\n0\n");
}

TEST(Log, DisabledLogWritesNothing) {
  LogDirectory log;
  EXPECT_FALSE(log.enabled());
  auto& s = log.stream("x", {"a"});
  s.row({1.0, 2.0, 3.0});  // ignored, even with a wrong count
  EXPECT_FALSE(s.enabled());
  TempDir dir;
  const auto file = dir.write("plain_file", "x");
  EXPECT_THROW(CsvWriter(file + "/a.csv", {"a"}), InvalidInput);  // parent is a file
}

namespace {
// A full disk, without privileges: RLIMIT_FSIZE makes write(2) fail with EFBIG past `bytes`
// (SIGXFSZ ignored), exactly where ENOSPC would. Restored when the guard goes.
struct FileSizeLimit {
  rlimit old{};
  void (*old_handler)(int) = nullptr;
  explicit FileSizeLimit(rlim_t bytes) {
    getrlimit(RLIMIT_FSIZE, &old);
    old_handler = std::signal(SIGXFSZ, SIG_IGN);
    rlimit lim = old;
    lim.rlim_cur = bytes;
    setrlimit(RLIMIT_FSIZE, &lim);
  }
  ~FileSizeLimit() {
    setrlimit(RLIMIT_FSIZE, &old);
    std::signal(SIGXFSZ, old_handler);
  }
};
}  // namespace

TEST(Files, AFullDiskNamesTheFileAndLeavesTheOldContent) {
  TempDir dir;
  const auto path = dir.write("summary.json", "old");
  {
    FileSizeLimit full(4096);
    try {
      writeTextFileAtomic(path, std::string(100000, 'x'));
      FAIL() << "a write past the limit succeeded";
    } catch (const IoError& e) {  // the system refused: a runtime error, not bad input
      const std::string msg = e.what();
      EXPECT_NE(msg.find(path), std::string::npos) << msg;
      EXPECT_NE(msg.find("cannot write"), std::string::npos) << msg;
    }
  }
  EXPECT_EQ(slurp(path), "old");
  EXPECT_EQ(dir.count(), 1u);  // no temporary left behind
}

TEST(Files, SummaryOfAnInterruptedRunSaysSo) {
  TempDir dir;
  const auto path = dir.file("s.json");
  nlohmann::json j;
  j["throws"] = 3;
  writeSummaryFile(path, j);
  EXPECT_FALSE(readJsonFile(path).contains("interrupted"));
  viewline::core::noteInterrupt(SIGINT);
  writeSummaryFile(path, j);
  viewline::core::clearInterrupt();
  const auto got = readJsonFile(path);
  EXPECT_EQ(got["interrupted"], true);
  EXPECT_EQ(got["interrupt_signal"], "SIGINT");
  EXPECT_EQ(got["throws"], 3);
}

TEST(Log, CsvAppearsWholeAtTheFirstFlushThenGrows) {
  TempDir dir;
  LogDirectory log(dir.file("log"));
  auto& s = log.stream("x", {"t"});
  s.row({1.0});
  EXPECT_FALSE(std::filesystem::exists(dir.file("log/x.csv")));  // only the hidden temporary so far
  log.flush();
  EXPECT_EQ(slurp(dir.file("log/x.csv")), "t\n1\n");
  s.row({2.0});
  log.flush();
  EXPECT_EQ(slurp(dir.file("log/x.csv")), "t\n1\n2\n");
  s.close();
  s.row({3.0});  // closed: discarded
  EXPECT_EQ(slurp(dir.file("log/x.csv")), "t\n1\n2\n");
  std::size_t n = 0;
  for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(dir.path / "log")) ++n;
  EXPECT_EQ(n, 1u);
}

TEST(Log, AFullDiskThrowsNamingTheLogAndLeavesNoPartialFile) {
  TempDir dir;
  const std::string path = dir.file("log/big.csv");
  {
    LogDirectory log(dir.file("log"));
    auto& s = log.stream("big", {"a", "b", "c"});
    FileSizeLimit full(8192);
    try {
      for (int i = 0; i < 100000; ++i) s.row({1.0 * i, 2.0 * i, 3.0 * i});
      log.flush();
      FAIL() << "no error past the file size limit";
    } catch (const IoError& e) {
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    }
    EXPECT_FALSE(s.enabled());  // the log ended at the error
  }
  EXPECT_FALSE(std::filesystem::exists(path));
  std::size_t n = 0;
  for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(dir.path / "log")) ++n;
  EXPECT_EQ(n, 0u);
}
