// SPDX-License-Identifier: MIT
// The exceptions bounce throws on purpose. A UserError is the user's to fix: bad input, a
// request beyond a limit the user set, a system with no physical solution; its message is one
// line that names the file, option or patch concerned. The front ends show it as it is (the
// command line exits with code 2; Python raises ValueError, FileNotFoundError, MemoryError or
// ArithmeticError). Any other exception is a programmer error, a bug in bounce (the command
// line exits with code 1). Interrupted is neither: work stopped on request.
#pragma once

#include <stdexcept>

namespace bounce {

/// An error the user can fix; see the file comment.
class UserError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

/// Bad user input: a missing or malformed file, a bad value, an empty scene. The message
/// already names the file and line (or the face, or the option).
class InputError : public UserError {
public:
    using UserError::UserError;
};

/// An input file that does not exist (the Python module raises FileNotFoundError for it).
class MissingFileError : public InputError {
public:
    using InputError::InputError;
};

/// A request for more memory (or more patches) than the user allowed.
class ResourceLimitError : public UserError {
public:
    using UserError::UserError;
};

/// The radiosity system is singular or otherwise cannot be solved as asked (reflectance at or
/// near 1 in a closed scene).
class SingularSystemError : public UserError {
public:
    using UserError::UserError;
};

/// Work stopped on request (a signal, a cancel flag) before it had a result.
class Interrupted : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

}  // namespace bounce
