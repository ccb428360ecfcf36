#pragma once
// The common result of every detector: a time-stamped measurement, or the
// reason why there is none. A detector never returns a value it does not
// trust: when the object is missing, clipped by the image border, too small or
// ambiguous, the caller gets a Failure that says so (enum + human text).

#include <Eigen/Core>
#include <string>
#include <utility>
#include <variant>

#include "viewline/core/error.h"
#include "viewline/core/time.h"

namespace viewline::vision {

/// Why a detector returned no measurement.
enum class FailureReason {
  NotFound,       ///< nothing matching the object in the searched region
  Clipped,        ///< the object touches the image border (or the crop margin)
  TooSmall,       ///< something was found but it is below the minimum size
  Ambiguous,      ///< several candidates score alike; picking one would be a guess
  TooFewCorners,  ///< table: fewer than four valid corners (clipped, edge-on, occluded)
  PoseFailed,     ///< PnP gave no (or a non-physical) solution
  NoReference,    ///< a prerequisite measurement (e.g. the table pose) is missing
};

/// Name of a failure reason ("not found", "clipped", "too small", ...), for logs and summaries.
const char* toString(FailureReason reason);

/// Why a detector returned no measurement, with a message for logs.
struct Failure {
  FailureReason reason = FailureReason::NotFound;  ///< the kind of failure
  std::string message;  ///< what exactly went wrong, for logs
};

/// Confidence class of a measurement.
enum class Quality {
  Good,      ///< the object looks as expected (round, unclipped, well inside the image)
  Degraded,  ///< usable, but partly occluded / off-shape; its covariance is inflated
};

/// Name of a quality class ("good", "degraded").
const char* toString(Quality quality);

/// Fields every detection carries. Pixels follow ViSP/OpenCV: u right, v down,
/// (0,0) the centre of the top-left pixel. The covariance is in px².
struct Measurement {
  core::Timestamp stamp = 0.0;                                 ///< capture time of the image (s)
  Eigen::Vector2d pixel = Eigen::Vector2d::Zero();             ///< (u, v) in full-resolution pixels
  Eigen::Matrix2d pixel_covariance = Eigen::Matrix2d::Identity();  ///< px²
  Quality quality = Quality::Good;  ///< Good, or Degraded (covariance inflated)
  double score = 0.0;  ///< detector-specific confidence in [0, 1] (1 = perfect)
};

/// Either a measurement of type T or a Failure. Accessing the wrong
/// alternative throws core::Error (a programming error, never silent).
template <class T>
class Result {
public:
  /// A successful result holding `value`.
  Result(T value) : data_(std::move(value)) {}  // NOLINT(google-explicit-constructor)
  /// A failed result holding `failure`.
  Result(Failure failure) : data_(std::move(failure)) {}  // NOLINT(google-explicit-constructor)
  /// A failed result with this reason and message.
  static Result fail(FailureReason reason, std::string message) {
    return Result(Failure{reason, std::move(message)});
  }

  /// True when the result holds a measurement.
  bool ok() const { return std::holds_alternative<T>(data_); }
  /// Same as ok().
  explicit operator bool() const { return ok(); }

  /// The measurement; throws core::Error when the result is a failure.
  const T& value() const {
    if (!ok()) throw core::Error(std::string("vision::Result: no measurement (") +
                                 toString(failure().reason) + ": " + failure().message + ")");
    return std::get<T>(data_);
  }
  /// The measurement; throws core::Error when the result is a failure.
  T& value() {
    if (!ok()) throw core::Error(std::string("vision::Result: no measurement (") +
                                 toString(failure().reason) + ": " + failure().message + ")");
    return std::get<T>(data_);
  }
  /// Member access to the measurement; throws core::Error when the result is a failure.
  const T* operator->() const { return &value(); }
  /// The failure; throws core::Error when the result holds a measurement.
  const Failure& failure() const {
    if (ok()) throw core::Error("vision::Result: failure() called on a successful result");
    return std::get<Failure>(data_);
  }

private:
  std::variant<T, Failure> data_;
};

}  // namespace viewline::vision
