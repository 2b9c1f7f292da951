// SPDX-License-Identifier: MIT
#pragma once

#include <stdexcept>
#include <string>

namespace bounce {

/// Bad user input: a missing or malformed file, a bad value, an empty scene.
/// The message already names the file and line (or the face); the CLI prints it as one
/// line and exits with code 2.
class InputError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

}  // namespace bounce
