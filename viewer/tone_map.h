// SPDX-License-Identifier: MIT
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "mesh/scene/rgb.h"

namespace bounce {

/// Radiosity is linear light; a display wants bounded, gamma-encoded values. Exposure scales
/// B so that the area-weighted mean luminance of the non-emitting patches (of all patches when
/// every one emits, as in a furnace) lands at 0.5, times 2^EV; the tone curve 1 - exp(-x)
/// rolls highlights off smoothly; then the sRGB transfer function (IEC 61966-2-1) encodes.
struct ToneMap {
    double scale = 1.0;  // linear factor applied to radiosity before the tone curve

    /// scale = 2^ev * 0.5 / (area-weighted mean luminance of patches that do not emit, or of
    /// all patches when every one emits).
    static ToneMap automatic(const std::vector<Rgb>& radiosity, const std::vector<Rgb>& emission,
                             const std::vector<double>& area, double ev);
    /// Display colour, 8 bits per channel.
    std::array<std::uint8_t, 3> operator()(const Rgb& b) const;
};

/// sRGB encoding of a linear value in [0,1].
double srgb_encode(double linear);

}  // namespace bounce
