// SPDX-License-Identifier: MIT
// The light of photons that land smooth, estimated once at each vertex of the mesh the point
// data is over, for the eye pass to interpolate with the radiosity: a wide density estimate at
// a few thousand vertices instead of a narrow, noisy one at every eye ray. The light pass sends
// here the photons turned only by the outsides of spheres (CausticPhoton::diverging: convex
// mirrors spread light out) and those sent from the lit patches (sources as wide as walls,
// which a sphere images as a wide blur).
#pragma once

#include <vector>

#include "mesh/meshing/patch_mesh.h"
#include "mesh/scene/rgb.h"
#include "solver/two_pass/caustic_map.h"
#include "solver/two_pass/patch_scene_tracer.h"

namespace bounce {

/// rho E at each vertex of `mesh` (W per unit area per channel, to add to its radiosity), E
/// the irradiance estimate of `map` there (CausticMap::irradiance, on the front of a cell
/// around the vertex, whose reflectance is rho), divided by the cone-weighted share of the
/// estimate's disc that lies on a patch facing the same way: a disc reaching past a crease, an
/// edge or a cut finds no photons beyond it, and would otherwise darken every vertex within
/// its radius of one. The share is sampled by short rays of `tracer`, which traces `mesh`.
std::vector<Rgb> spread_photon_light(const CausticMap& map, const PatchMesh& mesh, const PatchSceneTracer& tracer);

}  // namespace bounce
