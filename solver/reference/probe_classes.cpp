// SPDX-License-Identifier: MIT
#include "solver/reference/probe_classes.h"

#include <algorithm>
#include <cmath>

namespace bounce {

std::string to_string(ProbeClass c) {
    switch (c) {
        case ProbeClass::lit:
            return "lit";
        case ProbeClass::penumbra:
            return "penumbra";
        case ProbeClass::unlit:
            return "unlit";
        case ProbeClass::contact:
            return "contact";
    }
    return "?";
}

ProbeClass classify_probe(const PathTracer& tracer, const SurfacePoint& x, std::uint64_t seed,
                          const ProbeClassRule& rule) {
    if (tracer.clearance(x, rule.clearance_rays, seed) < rule.contact_share * tracer.diagonal())
        return ProbeClass::contact;
    const double share = tracer.direct_light_share(x, rule.light_samples, seed);
    if (share >= rule.lit_share) return ProbeClass::lit;
    if (share <= 1.0 - rule.lit_share) return ProbeClass::unlit;
    return ProbeClass::penumbra;
}

std::vector<SurfacePoint> probes_by_class(const PathTracer& tracer, std::size_t n, std::uint64_t seed,
                                          std::vector<ProbeClass>& classes, const ProbeClassRule& rule) {
    const std::vector<SurfacePoint> candidates = tracer.probes(16 * n, seed);
    std::array<std::vector<std::size_t>, 4> by_class;
    for (std::size_t k = 0; k < candidates.size(); ++k)
        by_class[std::size_t(classify_probe(tracer, candidates[k], seed + k, rule))].push_back(k);
    // Within a class, candidates are spread evenly over its area order, not its first n/4.
    const std::array<ProbeClass, 4> turn = {ProbeClass::penumbra, ProbeClass::contact, ProbeClass::unlit,
                                            ProbeClass::lit};
    std::array<std::size_t, 4> quota{};
    std::size_t given = 0;
    for (bool any = true; given < n && any;) {
        any = false;
        for (const ProbeClass c : turn)
            if (given < n && quota[std::size_t(c)] < by_class[std::size_t(c)].size()) {
                ++quota[std::size_t(c)];
                ++given;
                any = true;
            }
    }
    std::vector<SurfacePoint> out;
    classes.clear();
    for (const ProbeClass c : turn) {
        const auto& list = by_class[std::size_t(c)];
        const std::size_t q = quota[std::size_t(c)];
        for (std::size_t j = 0; j < q; ++j) {
            out.push_back(candidates[list[j * list.size() / q]]);
            classes.push_back(c);
        }
    }
    return out;
}

std::array<ClassScore, 4> score_by_class(const ProbeScore& score, std::span<const ProbeClass> classes) {
    std::array<ClassScore, 4> out{};
    std::array<double, 4> sum_smooth{}, sum_patch{};
    for (std::size_t k = 0; k < classes.size() && k < score.smooth_error.size(); ++k) {
        const double s = score.smooth_error[k], p = score.patch_error[k];
        if (std::isnan(s) || std::isnan(p)) continue;
        const std::size_t c = std::size_t(classes[k]);
        ClassScore& cs = out[c];
        ++cs.scored;
        sum_smooth[c] += s * s;
        sum_patch[c] += p * p;
        cs.max_smooth = std::max(cs.max_smooth, std::abs(s));
        cs.max_patch = std::max(cs.max_patch, std::abs(p));
    }
    for (std::size_t c = 0; c < 4; ++c)
        if (out[c].scored) {
            out[c].rms_smooth = std::sqrt(sum_smooth[c] / double(out[c].scored));
            out[c].rms_patch = std::sqrt(sum_patch[c] / double(out[c].scored));
        }
    return out;
}

}  // namespace bounce
