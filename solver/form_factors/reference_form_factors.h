// SPDX-License-Identifier: MIT
// Closed-form form factors (Howell's catalog of configuration factors), the references that
// tests and the accuracy example measure every method against.
#pragma once

#include <cmath>
#include <numbers>

namespace bounce {

/// Parallel, directly opposed, identical a x b rectangles at distance c.
inline double parallel_rectangles(double a, double b, double c) {
    const double X = a / c, Y = b / c, pi = std::numbers::pi;
    return 2.0 / (pi * X * Y) *
           (std::log(std::sqrt((1 + X * X) * (1 + Y * Y) / (1 + X * X + Y * Y))) +
            X * std::sqrt(1 + Y * Y) * std::atan(X / std::sqrt(1 + Y * Y)) +
            Y * std::sqrt(1 + X * X) * std::atan(Y / std::sqrt(1 + X * X)) - X * std::atan(X) - Y * std::atan(Y));
}

/// Perpendicular rectangles with a common edge of length l: from w x l to h x l.
inline double perpendicular_rectangles(double h, double w, double l) {
    const double H = h / l, W = w / l, pi = std::numbers::pi;
    const double H2 = H * H, W2 = W * W;
    const double t = std::log((1 + W2) * (1 + H2) / (1 + W2 + H2)) +
                     W2 * std::log(W2 * (1 + W2 + H2) / ((1 + W2) * (W2 + H2))) +
                     H2 * std::log(H2 * (1 + H2 + W2) / ((1 + H2) * (H2 + W2)));
    return 1.0 / (pi * W) *
           (W * std::atan(1 / W) + H * std::atan(1 / H) - std::sqrt(H2 + W2) * std::atan(1 / std::sqrt(H2 + W2)) +
            0.25 * t);
}

/// Coaxial parallel disks, radii r1 (emitter) and r2, at distance h.
inline double coaxial_disks(double r1, double r2, double h) {
    const double R1 = r1 / h, R2 = r2 / h;
    const double X = 1 + (1 + R2 * R2) / (R1 * R1);
    return 0.5 * (X - std::sqrt(X * X - 4 * (R2 / R1) * (R2 / R1)));
}

/// Differential area to a parallel a x b rectangle whose corner is straight above it at
/// height c (Howell B-3).
inline double point_to_rectangle_corner(double a, double b, double c) {
    const double A = a / c, B = b / c;
    return 1.0 / (2 * std::numbers::pi) *
           (A / std::sqrt(1 + A * A) * std::atan(B / std::sqrt(1 + A * A)) +
            B / std::sqrt(1 + B * B) * std::atan(A / std::sqrt(1 + B * B)));
}

}  // namespace bounce
