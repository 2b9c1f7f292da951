// SPDX-License-Identifier: MIT
#pragma once

#include <string>

namespace bounce {

/// A colour quantity per RGB channel: radiosity (W/m^2 per channel), emission,
/// reflectance or power. A type of its own so a position can never be added to a colour.
struct Rgb {
    double r = 0, g = 0, b = 0;

    constexpr Rgb() = default;
    constexpr Rgb(double r_, double g_, double b_) : r(r_), g(g_), b(b_) {}
    static constexpr Rgb gray(double v) { return {v, v, v}; }

    constexpr double& operator[](int c) { return c == 0 ? r : (c == 1 ? g : b); }
    constexpr double operator[](int c) const { return c == 0 ? r : (c == 1 ? g : b); }

    constexpr Rgb& operator+=(const Rgb& o) {
        r += o.r;
        g += o.g;
        b += o.b;
        return *this;
    }
    constexpr Rgb& operator-=(const Rgb& o) {
        r -= o.r;
        g -= o.g;
        b -= o.b;
        return *this;
    }
    constexpr Rgb& operator*=(double s) {
        r *= s;
        g *= s;
        b *= s;
        return *this;
    }
    friend constexpr Rgb operator+(Rgb a, const Rgb& b) { return a += b; }
    friend constexpr Rgb operator-(Rgb a, const Rgb& b) { return a -= b; }
    friend constexpr Rgb operator*(Rgb a, double s) { return a *= s; }
    friend constexpr Rgb operator*(double s, Rgb a) { return a *= s; }
    /// Channel-wise product, e.g. reflectance times irradiance.
    friend constexpr Rgb operator*(const Rgb& a, const Rgb& b) { return {a.r * b.r, a.g * b.g, a.b * b.b}; }
    friend constexpr bool operator==(const Rgb&, const Rgb&) = default;

    constexpr double sum() const { return r + g + b; }
    constexpr double max() const { return r > g ? (r > b ? r : b) : (g > b ? g : b); }
    constexpr double min() const { return r < g ? (r < b ? r : b) : (g < b ? g : b); }
    /// Rec. 709 luminance weights.
    constexpr double luminance() const { return 0.2126 * r + 0.7152 * g + 0.0722 * b; }

    std::string to_string() const;
};

}  // namespace bounce
