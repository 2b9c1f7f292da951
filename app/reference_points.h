// SPDX-License-Identifier: MIT
// The path-traced reference as `reference` writes it and `compare` scores against it.
#pragma once

#include <atomic>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "mesh/scene/scene.h"
#include "solver/reference/path_tracer.h"
#include "solver/reference/probe_classes.h"
#include "solver/reference/reference_csv.h"

namespace bounce::app {

/// Probes written by --probes: their positions and normals as input columns, and their class
/// (ProbeClass) when `classes` is given.
CsvTable probe_table(std::span<const SurfacePoint> probes, std::span<const ProbeClass> classes = {});

/// The class of every reference point, found on the scene (a point no surface holds: lit, and
/// never scored).
std::vector<ProbeClass> probe_classes(const Scene& scene, std::span<const ReferencePoint> reference);

/// Estimates every point (skipping those without a surface) with a progress line on a
/// terminal, honouring Ctrl-C, and returns `input` with the columns
/// B_r,B_g,B_b,se_r,se_g,se_b,paths,surface,status appended. `points[k]` empty: no surface
/// (status "missing", empty values).
CsvTable estimate_table(const PathTracer& tracer, const CsvTable& input,
                        const std::vector<std::optional<SurfacePoint>>& points, const ReferenceOptions& options,
                        bool show_progress);

/// For compare: the reference given by --reference, or (when `given` is empty) probes of
/// the scene drawn a class at a time (probes_by_class) and estimated at the default target and cached in `folder` under
/// a name that holds a hash of the scene, so a changed scene never reuses a stale file.
std::vector<ReferencePoint> reference_for_compare(const Scene& scene, const std::string& given,
                                                  const std::filesystem::path& folder, bool quiet);

/// Probes that compare draws when it makes its own reference.
inline constexpr std::size_t kCompareProbes = 128;

}  // namespace bounce::app
