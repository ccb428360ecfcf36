#include "viewline/vision/detection.h"

namespace viewline::vision {

const char* toString(FailureReason reason) {
  switch (reason) {
    case FailureReason::NotFound: return "not found";
    case FailureReason::Clipped: return "clipped";
    case FailureReason::TooSmall: return "too small";
    case FailureReason::Ambiguous: return "ambiguous";
    case FailureReason::TooFewCorners: return "too few corners";
    case FailureReason::PoseFailed: return "pose failed";
    case FailureReason::NoReference: return "no reference";
  }
  return "unknown";
}

const char* toString(Quality quality) {
  switch (quality) {
    case Quality::Good: return "good";
    case Quality::Degraded: return "degraded";
  }
  return "unknown";
}

}  // namespace viewline::vision
