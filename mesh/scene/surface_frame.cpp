// SPDX-License-Identifier: MIT
#include "mesh/scene/surface_frame.h"

#include <algorithm>
#include <cmath>

#include "mesh/scene/polygon.h"

namespace bounce::discontinuity {

Frame frame_of(const std::vector<V>& poly) {
    Frame f;
    if (poly.size() < 3) return f;
    const V n = newell_normal(poly);
    const double len = glm::length(n);
    if (!(len > 0)) return f;
    f.normal = n / len;
    f.area = 0.5 * len;
    f.origin = polygon_centroid(poly);
    // The longest edge as e1: well defined for slivers too.
    std::size_t best = 0;
    double longest = -1;
    for (std::size_t k = 0; k < poly.size(); ++k)
        if (const double l = glm::length(poly[(k + 1) % poly.size()] - poly[k]); l > longest) {
            longest = l;
            best = k;
        }
    V e1 = poly[(best + 1) % poly.size()] - poly[best];
    e1 -= glm::dot(e1, f.normal) * f.normal;
    if (!(glm::length(e1) > 0)) return f;
    f.e1 = glm::normalize(e1);
    f.e2 = glm::cross(f.normal, f.e1);
    f.valid = true;
    return f;
}

bool inside_polygon(const P2& p, const std::vector<P2>& poly) {
    bool in = false;
    for (std::size_t i = 0, j = poly.size() - 1; i < poly.size(); j = i++) {
        const P2& a = poly[i];
        const P2& b = poly[j];
        if ((a.y > p.y) != (b.y > p.y) && p.x < (b.x - a.x) * (p.y - a.y) / (b.y - a.y) + a.x) in = !in;
    }
    return in;
}

std::vector<std::pair<double, double>> inside_intervals(const P2& a, const P2& b, const std::vector<P2>& poly) {
    std::vector<double> ts = {0.0, 1.0};
    const P2 d = b - a;
    for (std::size_t k = 0; k < poly.size(); ++k) {
        const P2& p = poly[k];
        const P2 e = poly[(k + 1) % poly.size()] - p;
        const double den = cross2(d, e);
        if (den == 0) continue;
        const double t = cross2(p - a, e) / den, u = cross2(p - a, d) / den;
        if (t > 0 && t < 1 && u >= 0 && u <= 1) ts.push_back(t);
    }
    std::sort(ts.begin(), ts.end());
    std::vector<std::pair<double, double>> out;
    for (std::size_t k = 0; k + 1 < ts.size(); ++k) {
        if (!(ts[k + 1] - ts[k] > 1e-12)) continue;
        if (!inside_polygon(a + 0.5 * (ts[k] + ts[k + 1]) * d, poly)) continue;
        if (!out.empty() && std::abs(out.back().second - ts[k]) <= 1e-12)
            out.back().second = ts[k + 1];
        else
            out.emplace_back(ts[k], ts[k + 1]);
    }
    return out;
}

/// Removes from `intervals` the part of the segment inside convex `hole` (counter-clockwise).
void subtract_convex_interval(std::vector<std::pair<double, double>>& intervals, const P2& a, const P2& b,
                              const std::vector<P2>& hole) {
    // Cyrus-Beck: the segment's part inside every edge's left half-plane.
    double lo = 0.0, hi = 1.0;
    const P2 d = b - a;
    for (std::size_t k = 0; k < hole.size() && lo < hi; ++k) {
        const P2& p = hole[k];
        const P2 e = hole[(k + 1) % hole.size()] - p;
        const double f0 = cross2(e, a - p), fd = cross2(e, d);  // f(t) = f0 + t fd >= 0 inside
        if (fd == 0) {
            if (f0 < 0) hi = lo;
        } else if (fd > 0) {
            lo = std::max(lo, -f0 / fd);
        } else {
            hi = std::min(hi, -f0 / fd);
        }
    }
    if (!(hi - lo > 1e-12)) return;
    std::vector<std::pair<double, double>> out;
    for (const auto& [s, e] : intervals) {
        if (e <= lo || s >= hi) {
            out.emplace_back(s, e);
            continue;
        }
        if (lo - s > 1e-12) out.emplace_back(s, lo);
        if (e - hi > 1e-12) out.emplace_back(hi, e);
    }
    intervals = std::move(out);
}

}  // namespace bounce::discontinuity
