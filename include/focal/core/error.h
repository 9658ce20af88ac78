#pragma once
/// \file error.h
/// The one error hierarchy of focal. Errors are thrown at the API and I/O boundaries with a
/// message a user can act on (file, element index, what is wrong). Numerical degeneracies at a
/// vertex are never errors: they are status flags (and NaN values) in the results.

#include <stdexcept>
#include <string>

namespace focal {

/// Base class of every exception focal throws.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The caller passed arrays or options that violate a documented precondition
/// (wrong shapes, indices out of range, non-finite values where finite ones are required...).
class InvalidInput : public Error {
 public:
  using Error::Error;
};

/// A file could not be read or written, or its contents are malformed.
/// The message names the file and, where known, the line, byte offset or element index.
class IoError : public Error {
 public:
  using Error::Error;
};

/// A GPU was asked for but is not available (no CUDA in this build, no device, or a CUDA error).
class DeviceError : public Error {
 public:
  using Error::Error;
};

/// The caller asked a call to stop (Execution::cancel); nothing it would have returned exists.
class Cancelled : public Error {
 public:
  using Error::Error;
};

}  // namespace focal
