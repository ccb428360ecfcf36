#include "viewline/runtime/progress.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <string>

using viewline::runtime::Progress;

namespace {
std::string run(int interactive, long total) {
  std::FILE* f = std::tmpfile();
  {
    Progress p("throws", total, f, interactive, 1e9);
    for (long i = 1; i <= total; ++i) p.update(i);
  }
  std::rewind(f);
  std::string s;
  for (int c; (c = std::fgetc(f)) != EOF;) s.push_back(static_cast<char>(c));
  std::fclose(f);
  return s;
}
}  // namespace

TEST(Progress, AFileGetsPlainLinesEveryTenthAndTheLast) {
  const std::string s = run(0, 100);
  EXPECT_EQ(s.find('\r'), std::string::npos);
  EXPECT_NE(s.find("  throws 10 / 100\n"), std::string::npos) << s;
  EXPECT_NE(s.find("  throws 100 / 100\n"), std::string::npos) << s;
  long lines = 0;
  for (char c : s) lines += c == '\n';
  EXPECT_EQ(lines, 10);
}

TEST(Progress, ATerminalRedrawsInPlaceAndEndsTheLine) {
  const std::string s = run(1, 3);
  EXPECT_EQ(s, "\r  throws 1 / 3\r  throws 2 / 3\r  throws 3 / 3\n");
}

TEST(Progress, QuietPrintsNothing) {
  Progress q = Progress::quiet();
  q.update(5);
  q.finish();
  EXPECT_FALSE(q.interactive());
}
