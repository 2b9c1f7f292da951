// SPDX-License-Identifier: MIT
// Probes sorted by what makes a point hard for a radiosity mesh: whether the emitters' direct
// light reaches it whole, in part (a penumbra) or not at all, and whether another surface lies
// close in front of it (a contact, a lamp hung just below a ceiling).
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "solver/reference/path_tracer.h"
#include "solver/reference/probe_score.h"

namespace bounce {

enum class ProbeClass { lit, penumbra, unlit, contact };
inline constexpr std::array<ProbeClass, 4> kProbeClasses = {ProbeClass::lit, ProbeClass::penumbra, ProbeClass::unlit,
                                                            ProbeClass::contact};
std::string to_string(ProbeClass c);

/// How a probe is classed. A point whose front hemisphere meets a surface nearer than
/// `contact_share` of the scene's diagonal is a contact; otherwise the share of the direct
/// light's kernel that reaches it unblocked decides: at least `lit_share` lit, at most
/// 1 - lit_share (or no emitter facing it) unlit, a penumbra between.
struct ProbeClassRule {
    double contact_share = 0.025;
    double lit_share = 0.98;
    int light_samples = 256;  // per emitter
    int clearance_rays = 64;
};

ProbeClass classify_probe(const PathTracer& tracer, const SurfacePoint& x, std::uint64_t seed,
                          const ProbeClassRule& rule = {});

/// n probes spread so each class gets its share: candidates are drawn by area
/// (PathTracer::probes, 16 n of them), classed, and taken a class at a time in turn (penumbra,
/// contact, unlit, lit) in their area order, so a scene with a thin penumbra still gets a
/// quarter of its probes there; a class that runs out leaves its turns to the others.
/// `classes` receives each probe's class.
std::vector<SurfacePoint> probes_by_class(const PathTracer& tracer, std::size_t n, std::uint64_t seed,
                                          std::vector<ProbeClass>& classes, const ProbeClassRule& rule = {});

/// RMS and worst relative luminance error of the point data and of the patch values over the
/// scored probes of one class.
struct ClassScore {
    double rms_smooth = 0.0, max_smooth = 0.0, rms_patch = 0.0, max_patch = 0.0;
    std::size_t scored = 0;
};

/// A score split by class: entry k is class kProbeClasses[k]. `classes` runs parallel to the
/// reference the score was taken at.
std::array<ClassScore, 4> score_by_class(const ProbeScore& score, std::span<const ProbeClass> classes);

}  // namespace bounce
