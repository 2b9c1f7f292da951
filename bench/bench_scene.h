// SPDX-License-Identifier: MIT
#pragma once
// The scene every benchmark runs on: the Cornell box as the CLI loads it, meshed to
// BOUNCE_BENCH_PATCHES patches (default 2000, the CLI's default).

#include <cstdlib>
#include <string>

#include "mesh/meshing/patch_mesh.h"
#include "mesh/readers/scene_loader.h"

namespace bounce::bench {

inline std::size_t patch_target() {
    const char* env = std::getenv("BOUNCE_BENCH_PATCHES");
    return env ? std::size_t(std::stoul(env)) : 2000;
}

inline const PatchMesh& cornell() {
    static const PatchMesh mesh = [] {
        MeshingOptions o;
        o.target_patches = patch_target();
        // Without contact cuts: bench/run.py checks that both visibility backends block the same
        // share of rays, and the seams where a cut floor meets a block's foot are decided by
        // rounding (exact in CGAL, float in Embree); no patch sees through them.
        o.cut_contacts = false;
        return PatchMesh(load_scene("cornell"), o);
    }();
    return mesh;
}

}  // namespace bounce::bench
