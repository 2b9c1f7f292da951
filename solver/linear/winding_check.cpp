// SPDX-License-Identifier: MIT
#include "solver/linear/winding_check.h"

#include <algorithm>
#include <map>
#include <numeric>

#include "solver/form_factors/form_factor_estimator.h"

namespace bounce {

namespace {

constexpr std::size_t kRowsPerEmitter = 8;  // sampled patches per emitting surface
constexpr std::size_t kEmitters = 16;       // most powerful emitting surfaces looked at

}  // namespace

Patch turned(const Patch& p) {
    Patch q = p;
    std::reverse(q.vertices.begin(), q.vertices.begin() + q.vertex_count);
    q.normal = -p.normal;
    return q;
}

bool WindingReport::suspicious() const {
    return !dark_emitters.empty() || (escaped_fraction > 0.5 && reach_turned > reach_as_wound + 0.2);
}

WindingReport check_winding(const std::vector<Patch>& patches, const SolveResult& result) {
    WindingReport r;
    const double emitted = result.emitted_power.sum();
    if (!(emitted > 0) || patches.empty()) return r;
    r.escaped_fraction = (result.escaped_power + result.back_absorbed_power).sum() / emitted;

    // Emitting surfaces by power, and a few evenly spaced patches of each.
    std::map<int, std::vector<std::size_t>> by_surface;
    std::map<int, double> power;
    for (std::size_t i = 0; i < patches.size(); ++i)
        if (patches[i].emission.max() > 0) {
            by_surface[patches[i].surface].push_back(i);
            power[patches[i].surface] += patches[i].emission.sum() * patches[i].area;
        }
    std::vector<int> emitters;
    for (const auto& [s, p] : power) emitters.push_back(s);
    std::sort(emitters.begin(), emitters.end(), [&](int a, int b) { return power[a] > power[b]; });
    if (emitters.size() > kEmitters) emitters.resize(kEmitters);

    std::vector<Patch> flipped(patches.size());
    std::transform(patches.begin(), patches.end(), flipped.begin(), turned);
    const auto wound = make_form_factor_estimator("analytic", patches, nullptr, {});
    const auto turn = make_form_factor_estimator("analytic", flipped, nullptr, {});
    std::vector<float> row(patches.size());
    std::vector<double> gain(patches.size(), 0.0);  // per receiver: power landing if turned minus as wound
    double weight = 0.0, as_wound = 0.0, if_turned = 0.0;
    for (const int s : emitters) {
        const auto& ids = by_surface[s];
        const std::size_t step = std::max<std::size_t>(1, ids.size() / kRowsPerEmitter);
        double reached = 0.0;
        for (std::size_t k = 0; k < ids.size(); k += step) {
            const std::size_t i = ids[k];
            const double w = patches[i].emission.sum() * patches[i].area;
            wound->compute_row(i, row);
            double sum = 0.0;
            for (std::size_t j = 0; j < row.size(); ++j) {
                sum += row[j];
                gain[j] -= w * row[j];
            }
            reached += sum;
            as_wound += w * sum;
            turn->compute_row(i, row);
            sum = 0.0;
            for (std::size_t j = 0; j < row.size(); ++j) {
                sum += row[j];
                gain[j] += w * row[j];
            }
            if_turned += w * sum;
            weight += w;
        }
        if (!(reached > 0)) r.dark_emitters.push_back(s);
    }
    if (weight > 0) {
        r.reach_as_wound = as_wound / weight;
        r.reach_turned = if_turned / weight;
    }
    // The surfaces that gain most by turning; a dark emitter is itself a likely culprit.
    std::map<int, double> surface_gain;
    for (std::size_t j = 0; j < patches.size(); ++j)
        if (gain[j] > 0) surface_gain[patches[j].surface] += gain[j];
    std::vector<std::pair<double, int>> ranked;
    for (const auto& [s, g] : surface_gain) ranked.emplace_back(g, s);
    std::sort(ranked.rbegin(), ranked.rend());
    r.likely_faces = r.dark_emitters;
    for (const auto& [g, s] : ranked)
        if (r.likely_faces.size() < 5 &&
            std::find(r.likely_faces.begin(), r.likely_faces.end(), s) == r.likely_faces.end())
            r.likely_faces.push_back(s);
    if (r.likely_faces.size() > 5) r.likely_faces.resize(5);
    return r;
}

}  // namespace bounce
