#pragma once
// Error types shared by all modules. Bad input (a config key, a file, a
// measurement) raises InvalidInput with a message naming what was wrong and
// what was expected; nothing is changed when it is thrown.

#include <stdexcept>
#include <string>

namespace viewline::core {

/// Base of every error viewline throws.
class Error : public std::runtime_error {
public:
  using std::runtime_error::runtime_error;
};

/// Input that violates a documented precondition (NaN, wrong size, dt <= 0, a
/// non-positive-definite covariance, an unknown config key...).
class InvalidInput : public Error {
public:
  using Error::Error;
};

/// The system refused an operation on valid input: a full disk, a file size limit, an I/O error,
/// a read-only file system. Apps report it as a runtime error (exit 1), not a usage error.
class IoError : public Error {
public:
  using Error::Error;
};

/// A numerical failure that good input can still cause (e.g. a Riccati
/// iteration that does not converge).
class NumericalError : public Error {
public:
  using Error::Error;
};

}  // namespace viewline::core
