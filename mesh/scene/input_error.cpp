// SPDX-License-Identifier: MIT
#include "mesh/scene/input_error.h"

#include <sstream>

namespace bounce {

std::string number_text(double x) {
    std::ostringstream t;
    t << x;
    return t.str();
}

std::string out_of_range_text(const std::string& value, double lo, double hi) {
    return "out of range, got " + value + " (expected " + number_text(lo) + " to " + number_text(hi) + ")";
}

std::string not_positive_text(const std::string& value) {
    return "not a positive number, got '" + value + "' (expected > 0)";
}

std::string not_a_number_text(const std::string& value, double lo, double hi) {
    return "not a number, got '" + value + "' (expected " + number_text(lo) + " to " + number_text(hi) + ")";
}

}  // namespace bounce
