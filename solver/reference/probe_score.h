// SPDX-License-Identifier: MIT
// How far a radiosity solution is from the path-traced reference, at the reference's points.
#pragma once

#include <cstddef>
#include <span>
#include <vector>

#include "mesh/meshing/patch_mesh.h"
#include "mesh/scene/rgb.h"
#include "solver/reference/reference_csv.h"

namespace bounce {

/// Relative errors |B - B_ref| / B_ref at the probes, in luminance (RMS and max) and per
/// channel (RMS). "patch": the value of the patch under the probe, as the solver holds it
/// (piecewise constant); "smooth": the point data interpolated linearly over the cell's
/// triangles, as ParaView shows the .vtu.
struct ProbeScore {
    double rms_patch = 0.0, max_patch = 0.0;
    double rms_smooth = 0.0, max_smooth = 0.0;
    Rgb rms_patch_channel, rms_smooth_channel;
    std::size_t scored = 0;        // probes with a value, on a patch, and lit
    std::size_t skipped = 0;       // probes without a value, dark (B_ref below 1e-3 of the median), or on no patch
    double reference_noise = 0.0;  // RMS of the probes' relative standard errors (luminance): the floor of any score
    /// Per probe, in the reference's order: signed relative luminance errors (B - B_ref) / B_ref of
    /// the patch value and of the point data; NaN for a skipped probe.
    std::vector<double> patch_error, smooth_error;
};

/// Scores a solution on `mesh` (radiosity per patch) at the reference points. A probe lies on
/// a patch when it is within 1e-6 of the scene size of the patch's plane, inside its polygon,
/// and the normals agree.
/// `point_values`, when it has one value per mesh vertex, is the point data (gathered values);
/// otherwise the point data is area_weighted_vertex_values(mesh, patch_radiosity).
ProbeScore score_at_probes(const PatchMesh& mesh, std::span<const Rgb> patch_radiosity,
                           std::span<const ReferencePoint> reference, std::span<const Rgb> point_values = {});

}  // namespace bounce
