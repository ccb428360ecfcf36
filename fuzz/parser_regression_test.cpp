// Regressions for parser defects found by the fuzz targets (fuzz/README.md, "Findings"): each
// input must be refused with core::InvalidInput naming what was wrong, never another exception.

#include <gtest/gtest.h>

#include <string>

#include "viewline/core/error.h"
#include "viewline/io/config_edit.h"

namespace io = viewline::io;

namespace {
template <class F>
std::string invalidInputMessage(F&& f) {
  try {
    f();
  } catch (const viewline::core::InvalidInput& e) {
    return e.what();
  }
  return "(no InvalidInput)";
}
}  // namespace

// F1: std::stoi threw std::out_of_range on a list index beyond int; nothing caught it.
TEST(FuzzRegression, ListIndexBeyondIntIsInvalidInput) {
  const std::string msg = invalidInputMessage([] { io::parseKeyValue("cameras[99999999999].sigma_px=1"); });
  EXPECT_NE(msg.find("cameras[99999999999].sigma_px"), std::string::npos) << msg;
  EXPECT_NE(msg.find("too large"), std::string::npos) << msg;
  EXPECT_NO_THROW(io::parseDottedKey("cameras[999999999].sigma_px"));  // 9 digits: still an index
}
