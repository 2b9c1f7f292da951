// SPDX-License-Identifier: MIT
#include "solver/pipeline/quality.h"

namespace bounce {

QualityPreset quality_preset(Quality q) {
    switch (q) {
        case Quality::draft:
            return {1000, std::nullopt, "--patches 1000"};
        case Quality::standard:
            return {MeshingOptions{}.target_patches, std::nullopt, ""};
        case Quality::fine:
            return {8000, 0.01, "--patches 8000 --display-tolerance 0.01"};
    }
    return {};
}

void apply_quality(SolveRequest& r, bool meshing_given) {
    if (!r.quality) return;
    const QualityPreset p = quality_preset(*r.quality);
    if (!meshing_given) r.meshing.target_patches = p.patches;
    // Display cells replace the mesh, which elements and a series keep, and refine gathered
    // vertices: where they are off by default, the preset leaves them off.
    const bool cells = r.element_split == 1 && r.series.value_or(0) == 0 && r.gather == GatherMode::vertices;
    if (!r.display_tolerance && p.display_tolerance && cells) r.display_tolerance = p.display_tolerance;
}

}  // namespace bounce
