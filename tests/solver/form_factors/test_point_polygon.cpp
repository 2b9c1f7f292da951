// SPDX-License-Identifier: MIT
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "solver/form_factors/patch_sampling.h"
#include "solver/form_factors/point_polygon_form_factor.h"
#include "solver/form_factors/reference_form_factors.h"

using namespace bounce;
using V = glm::dvec3;

namespace {

/// Panels on [0,1] graded geometrically towards both ends, where the integrand of a
/// touching pair is singular in its derivative.
std::vector<std::pair<double, double>> graded_panels() {
    std::vector<double> cuts = {0.0};
    for (int k = 12; k >= 1; --k) cuts.push_back(0.5 * std::pow(0.25, k));
    cuts.push_back(0.5);
    for (int k = 1; k <= 12; ++k) cuts.push_back(1 - 0.5 * std::pow(0.25, k));
    cuts.push_back(1.0);
    std::vector<std::pair<double, double>> p;
    for (std::size_t i = 0; i + 1 < cuts.size(); ++i) p.emplace_back(cuts[i], cuts[i + 1]);
    return p;
}

/// (1/A) integral over the receiver rectangle origin + u*eu + v*ev of F(dA -> polygon).
double area_to_polygon(V origin, V eu, V ev, V normal, const std::vector<V>& poly) {
    std::vector<double> x, w;
    gauss_legendre(12, x, w);
    const auto panels = graded_panels();
    double sum = 0;
    for (auto [u0, u1] : panels)
        for (auto [v0, v1] : panels)
            for (int i = 0; i < 12; ++i)
                for (int j = 0; j < 12; ++j) {
                    const double u = u0 + (u1 - u0) * x[i], v = v0 + (v1 - v0) * x[j];
                    sum += w[i] * w[j] * (u1 - u0) * (v1 - v0) *
                           point_polygon_form_factor(origin + u * eu + v * ev, normal, poly);
                }
    return sum;
}

}  // namespace

TEST(AnalyticReferences, ReproduceTheValidationTables) {
    EXPECT_NEAR(parallel_rectangles(1, 1, 1), 0.199824896, 1e-9);
    EXPECT_NEAR(parallel_rectangles(2, 1, 1), 0.285875385, 1e-9);
    EXPECT_NEAR(parallel_rectangles(1, 1, 0.5), 0.415253284, 1e-9);
    EXPECT_NEAR(parallel_rectangles(1, 1, 2), 0.068589589, 1e-9);
    EXPECT_NEAR(parallel_rectangles(1, 1, 0.01), 0.980416603, 1e-9);
    EXPECT_NEAR(parallel_rectangles(1, 1, 0.001), 0.998005632, 1e-9);
    EXPECT_NEAR(perpendicular_rectangles(1, 1, 1), 0.200043776, 1e-9);
    EXPECT_NEAR(perpendicular_rectangles(2, 1, 1), 0.232852603, 1e-9);
    EXPECT_NEAR(perpendicular_rectangles(1, 2, 1), 0.116426301, 1e-9);
    EXPECT_NEAR(perpendicular_rectangles(1, 1, 0.5), 0.149299796, 1e-9);
    EXPECT_NEAR(coaxial_disks(1, 1, 1), 0.381966011, 1e-9);
    EXPECT_NEAR(coaxial_disks(0.5, 1, 1), 0.468871126, 1e-9);
    EXPECT_NEAR(coaxial_disks(1, 2, 0.5), 0.924816186, 1e-9);
}

TEST(PointPolygon, DiskAboveAPointIsRSquaredOverRSquaredPlusHSquared) {
    for (auto [r, h] : {std::pair{1.0, 1.0}, {0.5, 1.0}, {2.0, 0.5}}) {
        // Regular n-gon with the disk's area (so only the shape differs, by O(1/n^2)).
        const int n = 200000;
        const double R = r * std::sqrt(2 * std::numbers::pi / (n * std::sin(2 * std::numbers::pi / n)));
        std::vector<V> poly;
        for (int k = 0; k < n; ++k) {
            const double t = -2 * std::numbers::pi * k / n;  // clockwise from above: faces down
            poly.emplace_back(R * std::cos(t), R * std::sin(t), h);
        }
        EXPECT_NEAR(point_polygon_form_factor({0, 0, 0}, {0, 0, 1}, poly), r * r / (r * r + h * h), 1e-9);
    }
    // r = h gives exactly one half.
}

TEST(PointPolygon, PointBelowARectangleCornerMatchesTheClosedForm) {
    for (auto [a, b, c] : {std::tuple{1.0, 1.0, 1.0}, {2.0, 0.5, 0.3}, {0.1, 3.0, 2.0}}) {
        const std::vector<V> rect = {{0, 0, c}, {0, b, c}, {a, b, c}, {a, 0, c}};
        EXPECT_NEAR(point_polygon_form_factor({0, 0, 0}, {0, 0, 1}, rect), point_to_rectangle_corner(a, b, c), 1e-12);
    }
}

TEST(PointPolygon, PolygonBelowTheTangentPlaneIsClipped) {
    // A rectangle straddling the tangent plane: only the half above counts.
    const std::vector<V> full = {{1, -1, -1}, {1, 1, -1}, {1, 1, 1}, {1, -1, 1}};
    const std::vector<V> upper = {{1, -1, 0}, {1, 1, 0}, {1, 1, 1}, {1, -1, 1}};
    const double f = point_polygon_form_factor({0, 0, 0}, {0, 0, 1}, full);
    EXPECT_GT(f, 0.0);
    EXPECT_NEAR(f, point_polygon_form_factor({0, 0, 0}, {0, 0, 1}, upper), 1e-15);
    const std::vector<V> below = {{1, -1, -2}, {1, 1, -2}, {1, 1, -1}, {1, -1, -1}};
    EXPECT_EQ(point_polygon_form_factor({0, 0, 0}, {0, 0, 1}, below), 0.0);
}

TEST(PointPolygon, IntegratedOverTheReceiverGivesTheParallelTable) {
    for (auto [a, b, c] : {std::tuple{1.0, 1.0, 1.0}, {2.0, 1.0, 1.0}, {1.0, 1.0, 0.5}, {1.0, 1.0, 2.0}}) {
        const std::vector<V> top = {{0, 0, c}, {0, b, c}, {a, b, c}, {a, 0, c}};
        const double f = area_to_polygon({0, 0, 0}, {a, 0, 0}, {0, b, 0}, {0, 0, 1}, top);
        EXPECT_NEAR(f, parallel_rectangles(a, b, c), 1e-9) << a << " " << b << " " << c;
    }
}

TEST(PointPolygon, IntegratedOverTheReceiverGivesThePerpendicularTable) {
    for (auto [h, w, l] : {std::tuple{1.0, 1.0, 1.0}, {2.0, 1.0, 1.0}, {1.0, 2.0, 1.0}, {1.0, 1.0, 0.5}}) {
        // From rectangle 1 (w x l in z = 0) to rectangle 2 (h x l in x = 0), common edge on y.
        const std::vector<V> two = {{0, 0, 0}, {0, l, 0}, {0, l, h}, {0, 0, h}};
        const double f = area_to_polygon({0, 0, 0}, {w, 0, 0}, {0, l, 0}, {0, 0, 1}, two);
        EXPECT_NEAR(f, perpendicular_rectangles(h, w, l), 1e-9) << h << " " << w << " " << l;
    }
}
