// SPDX-License-Identifier: MIT
#pragma once

#include <string>

#include "mesh/scene/errors.h"  // InputError, MissingFileError

namespace bounce {

/// The one style of every range error, after the option, file and line it concerns:
/// "out of range, got V (expected LO to HI)" and "not a positive number, got 'V' (expected > 0)".
std::string out_of_range_text(const std::string& value, double lo, double hi);
std::string not_positive_text(const std::string& value);
/// "not a number, got 'V' (expected LO to HI)".
std::string not_a_number_text(const std::string& value, double lo, double hi);
/// A number as messages print it (the stream's default: 1e+08, 0.5).
std::string number_text(double x);

}  // namespace bounce
