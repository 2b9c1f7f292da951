// SPDX-License-Identifier: MIT
#include "viewer/tone_map.h"

#include <algorithm>
#include <cmath>

namespace bounce {

double srgb_encode(double x) {
    x = std::clamp(x, 0.0, 1.0);
    return x <= 0.0031308 ? 12.92 * x : 1.055 * std::pow(x, 1.0 / 2.4) - 0.055;
}

ToneMap ToneMap::automatic(const std::vector<Rgb>& radiosity, const std::vector<Rgb>& emission,
                           const std::vector<double>& area, double ev) {
    auto mean_luminance = [&](bool emitting_too) {
        double sum = 0.0, weight = 0.0;
        for (std::size_t i = 0; i < radiosity.size(); ++i) {
            if (!emitting_too && emission[i].max() > 0) continue;
            sum += radiosity[i].luminance() * area[i];
            weight += area[i];
        }
        return weight > 0 ? sum / weight : 0.0;
    };
    // A scene whose every patch emits (a furnace) has no surface to expose for but the lights.
    double mean = mean_luminance(false);
    if (!(mean > 0)) mean = mean_luminance(true);
    return {std::exp2(ev) * 0.5 / (mean > 0 ? mean : 1.0)};
}

std::array<std::uint8_t, 3> ToneMap::operator()(const Rgb& b) const {
    std::array<std::uint8_t, 3> out;
    for (int c = 0; c < 3; ++c) {
        const double x = std::max(0.0, b[c] * scale);
        out[c] = std::uint8_t(std::lround(255.0 * srgb_encode(1.0 - std::exp(-x))));
    }
    return out;
}

}  // namespace bounce
