#pragma once
// Private parameter checks shared by the model sources.

#include <sstream>
#include <string>

#include "viewline/core/checks.h"

namespace viewline::estimation::detail {

using core::requireNonNegative;

inline void requireDim(int dim, const std::string& what) {
  if (dim < 1 || dim > 3) {
    std::ostringstream s;
    s << what << " = " << dim << " (expected 1, 2 or 3)";
    throw core::InvalidInput(s.str());
  }
}

inline void requireDt(double dt, const std::string& model) { core::requirePositive(dt, model + ": dt"); }

}  // namespace viewline::estimation::detail
