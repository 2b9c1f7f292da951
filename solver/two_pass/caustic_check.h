// SPDX-License-Identifier: MIT
// The caustic measured two ways, to score the photon map against the path tracer: the power
// that mirrors and glass bring to a region of a diffuse plane, and the pixel of a picture
// where that light's irradiance peaks.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

#include "mesh/scene/rgb.h"
#include "solver/two_pass/eye_pass.h"

namespace bounce {

class CausticMap;
class PathTracer;

/// A disc on a diffuse plane of the scene: where the caustic is measured.
struct CausticRegion {
    glm::dvec3 centre{0.0};            // on the plane
    glm::dvec3 normal{0.0, 1.0, 0.0};  // the plane's unit front normal
    double radius = 0.0;               // scene units
};

/// The floor of cornell-spheres under its glass sphere, around where the line from the lamp's
/// centre through the sphere's centre meets it: the caustic is a ring about 35 mm across, and
/// the region a disc 50 mm in radius.
CausticRegion cornell_spheres_caustic_region();

/// The pixels the peak is sought in: a camera's picture, and the plane's points each pixel
/// spans (its footprint: the pixel's rays met with the region's plane, whatever lies between).
struct CausticView {
    PinholeCamera camera;
    int width = 512, height = 512;
};

/// What a caustic measure finds.
struct CausticMeasure {
    Rgb power;                       // W per channel landing in the region through mirrors and glass
    Rgb power_se;                    // its standard error (0 for the photon map: its photons are counted)
    int peak_col = -1;               // the pixel where that irradiance (mean over each footprint, luminance) peaks
    int peak_row = -1;               //   once smoothed by a Gaussian of sigma one pixel
    double peak = 0.0;               // the smoothed irradiance there, luminance, W per unit area
    double peak_se = 0.0;            // its standard error (0 for the photon map)
    std::size_t pixels = 0;          // pixels searched: those whose centre ray meets the plane in the region
    std::vector<int> searched;       // those pixels, row * width + col
    std::vector<double> irradiance;  // the mean irradiance over each one's footprint, luminance
};

/// The photon map's caustic: the power of its photons inside the region (on the plane, facing
/// its normal), and the peak of its irradiance estimate (CausticMap::irradiance, what the eye
/// pass shows) averaged over each pixel's footprint on a k x k grid of samples.
CausticMeasure measure_caustic(const CausticMap& map, const CausticRegion& region, const CausticView& view,
                               int samples_per_pixel = 64);

struct TracedCausticOptions {
    std::uint64_t region_points = 4096;  // points uniform over the region, 64 paths each
    std::uint64_t pixel_points = 16;     // points uniform over each pixel's footprint, 64 paths each
    bool emitted_only = false;           // light from the emitters alone (L S+ D): a map of the emitters' photons
    std::uint64_t seed = 1;
};

/// The path tracer's caustic (PathTracer::specular_irradiance): the power in the region as its
/// area times the mean irradiance at points uniform over it, and the peak of the pixels' mean
/// irradiance, each with the standard error from the spread of its points' estimates.
CausticMeasure measure_caustic(const PathTracer& tracer, const CausticRegion& region, const CausticView& view,
                               const TracedCausticOptions& options);

}  // namespace bounce
