// SPDX-License-Identifier: MIT
// The quality presets: named bundles of `bounce solve` settings, each a point on the measured
// speed/accuracy chart of the scenes with path-traced references (docs/guide/choosing-settings.md).
// A preset fills only what the request leaves open: an option given beside it wins.
#pragma once

#include <cstddef>
#include <optional>
#include <string>

#include "solver/pipeline/solve_request.h"

namespace bounce {

/// What a preset sets. The preset is for the patch solvers (any of them): with --adaptive or
/// the hierarchical solver only the standard one is accepted (validate()).
struct QualityPreset {
    std::size_t patches = 0;  // MeshingOptions::target_patches, unless a meshing is given
    /// The patch solvers' display tolerance (patch_display_refinement.h), unless one is given;
    /// unset: the request's own default.
    std::optional<double> display_tolerance;
    std::string flags;  // the `bounce solve` flags the preset stands for ("" for the standard one)
};

/// The settings of each preset.
QualityPreset quality_preset(Quality q);

/// Fills what request.quality sets and the request leaves open: the patch count when
/// `meshing_given` is false (no --patches, --max-area or --max-edge), the display tolerance when
/// none is given. Nothing without a quality; the standard preset changes nothing.
void apply_quality(SolveRequest& request, bool meshing_given);

}  // namespace bounce
