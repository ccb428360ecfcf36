#pragma once
// Helpers the scenario tests share.

#include <string>

#include "viewline/core/error.h"

namespace viewline::scenarios::test {

/// The message of the core::InvalidInput that f() throws ("" when it throws none).
template <class F>
std::string errorOf(F&& f) {
  try {
    f();
  } catch (const core::InvalidInput& e) {
    return e.what();
  }
  return "";
}

}  // namespace viewline::scenarios::test
