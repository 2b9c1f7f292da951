// SPDX-License-Identifier: MIT
// The exact polygon-to-polygon factor against the closed forms of shared/VALIDATION.md.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "solver/form_factors/point_polygon_form_factor.h"
#include "solver/form_factors/polygon_form_factor.h"
#include "solver/form_factors/reference_form_factors.h"

using namespace bounce;

namespace {

using Poly = std::vector<glm::dvec3>;

double rel(double got, double want) { return std::abs(got - want) / want; }

/// Howell C-11 (parallel rectangles in any offset position) as a corner sum: the factor from
/// [x1,x2]x[y1,y2] at z = 0 to [xi1,xi2]x[eta1,eta2] at z = c is
///     A1 F12 = sum (-1)^(i+j+k+l) G(x_i - xi_k, y_j - eta_l) over the 16 corners, with
///     G(x, y) = 1/(2 pi) [ x sqrt(y^2+c^2) atan(x/sqrt(y^2+c^2)) + y sqrt(x^2+c^2) atan(y/sqrt(x^2+c^2))
///                          - c^2/2 ln(x^2+y^2+c^2) ].
double parallel_offset(double x1, double x2, double y1, double y2, double e1, double e2, double n1, double n2,
                       double c) {
    const auto G = [c](double x, double y) {
        const double sy = std::sqrt(y * y + c * c), sx = std::sqrt(x * x + c * c);
        const double t = (x == 0 ? 0 : x * sy * std::atan(x / sy)) + (y == 0 ? 0 : y * sx * std::atan(y / sx)) -
                         0.5 * c * c * std::log(x * x + y * y + c * c);
        return t / (2 * std::numbers::pi);
    };
    const double xs[2] = {x1, x2}, ys[2] = {y1, y2}, es[2] = {e1, e2}, ns[2] = {n1, n2};
    double s = 0;
    for (int i = 0; i < 2; ++i)
        for (int j = 0; j < 2; ++j)
            for (int k = 0; k < 2; ++k)
                for (int l = 0; l < 2; ++l) s += ((i + j + k + l) % 2 ? -1 : 1) * G(xs[i] - es[k], ys[j] - ns[l]);
    return s / ((x2 - x1) * (y2 - y1));
}

Poly lower(double x1, double x2, double y1, double y2) { return {{x1, y1, 0}, {x2, y1, 0}, {x2, y2, 0}, {x1, y2, 0}}; }
Poly upper(double x1, double x2, double y1, double y2, double c) {
    return {{x1, y1, c}, {x1, y2, c}, {x2, y2, c}, {x2, y1, c}};
}

const glm::dvec3 up(0, 0, 1), down(0, 0, -1), east(1, 0, 0);

}  // namespace

TEST(PolygonFormFactor, ParallelRectanglesMatchHowellTo1e9) {
    // Every row of the parallel table, down to c = 0.001 (nearly touching), both ways round.
    for (auto [a, b, c, want] : {std::tuple{1.0, 1.0, 1.0, 0.199824896},
                                 {2.0, 1.0, 1.0, 0.285875385},
                                 {1.0, 1.0, 0.5, 0.415253284},
                                 {1.0, 1.0, 2.0, 0.068589589},
                                 {1.0, 1.0, 0.01, 0.980416603},
                                 {1.0, 1.0, 0.001, 0.998005632}}) {
        const double exact = parallel_rectangles(a, b, c);
        EXPECT_NEAR(exact, want, 5e-10);
        const double f = polygon_form_factor(lower(0, a, 0, b), up, upper(0, a, 0, b, c), down, 1e-10);
        const double g = polygon_form_factor(upper(0, a, 0, b, c), down, lower(0, a, 0, b), up, 1e-10);
        EXPECT_LT(rel(f, exact), 1e-9) << a << " " << b << " " << c << ": " << f;
        EXPECT_LT(rel(g, exact), 1e-9) << a << " " << b << " " << c << ": " << g;
    }
}

TEST(PolygonFormFactor, PerpendicularRectanglesWithACommonEdgeMatchHowellTo1e9) {
    for (auto [h, w, l, want] : {std::tuple{1.0, 1.0, 1.0, 0.200043776},
                                 {2.0, 1.0, 1.0, 0.232852603},
                                 {1.0, 2.0, 1.0, 0.116426301},
                                 {1.0, 1.0, 0.5, 0.149299796}}) {
        const double exact = perpendicular_rectangles(h, w, l);
        EXPECT_NEAR(exact, want, 5e-10);
        const Poly one = {{0, 0, 0}, {w, 0, 0}, {w, l, 0}, {0, l, 0}};  // z = 0, facing +z
        const Poly two = {{0, 0, 0}, {0, l, 0}, {0, l, h}, {0, 0, h}};  // x = 0, facing +x
        const double f = polygon_form_factor(one, up, two, east, 1e-10);
        EXPECT_LT(rel(f, exact), 1e-9) << h << " " << w << " " << l << ": " << f;
        // Reciprocity: A1 F12 = A2 F21.
        const double g = polygon_form_factor(two, east, one, up, 1e-10);
        EXPECT_LT(rel(h * g, w * f), 1e-9);
    }
}

TEST(PolygonFormFactor, OffsetParallelRectanglesMatchTheCornerSum) {
    // Howell C-11 in offset positions: near and far, overlapping and not, sharing a projected
    // edge (collinear in projection), and a small patch against a large one.
    struct Case {
        double x1, x2, y1, y2, e1, e2, n1, n2, c;
    };
    for (const Case& k : {Case{0, 1, 0, 1, 1, 2, 0, 1, 0.5}, Case{0, 1, 0, 1, 0.5, 1.5, 0.25, 0.75, 0.01},
                          Case{0, 0.1, 0, 0.1, 0.9, 1.0, 0.9, 1.0, 1.0}, Case{0, 0.05, 0, 0.05, 0, 1, 0, 1, 0.02},
                          Case{0, 1, 0, 1, 0, 1, 1, 2, 0.001}, Case{0, 3, 0, 1, 1, 2, 0.2, 0.3, 0.3}}) {
        const double exact = parallel_offset(k.x1, k.x2, k.y1, k.y2, k.e1, k.e2, k.n1, k.n2, k.c);
        const double f =
            polygon_form_factor(lower(k.x1, k.x2, k.y1, k.y2), up, upper(k.e1, k.e2, k.n1, k.n2, k.c), down, 1e-10);
        EXPECT_LT(std::abs(f - exact), 1e-9 * exact + 1e-15) << k.c << " " << k.e1 << ": " << f << " vs " << exact;
    }
    // The corner sum itself against the directly opposed closed form.
    EXPECT_LT(rel(parallel_offset(0, 1, 0, 1, 0, 1, 0, 1, 1), 0.199824896), 1e-8);
}

TEST(PolygonFormFactor, CoplanarBehindAndStraddlingPairs) {
    // Coplanar neighbours and polygons behind each other exchange nothing.
    EXPECT_EQ(polygon_form_factor(lower(0, 1, 0, 1), up, lower(1, 2, 0, 1), up), 0.0);
    EXPECT_EQ(polygon_form_factor(lower(0, 1, 0, 1), up, lower(3, 4, 0, 1), up), 0.0);
    EXPECT_EQ(polygon_form_factor(lower(0, 1, 0, 1), up, upper(0, 1, 0, 1, -1), down), 0.0);
    // Facing the wrong way: the upper plate faces up, away from the lower one.
    const Poly lid_facing_up = {{0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
    EXPECT_EQ(polygon_form_factor(lower(0, 1, 0, 1), up, lid_facing_up, up), 0.0);
    // A wall x = 0 from z = -1 to 1 facing +x, against the floor [0,1]^2 facing +z: only its
    // upper half sees the floor, which is the shared-edge table case (h = w = l = 1).
    const Poly wall = {{0, 0, -1}, {0, 1, -1}, {0, 1, 1}, {0, 0, 1}};
    const double f = polygon_form_factor(wall, east, lower(0, 1, 0, 1), up, 1e-10);
    EXPECT_LT(rel(f, 0.5 * 0.200043776), 1e-8) << f;  // A_wall = 2: F = F(half) / 2
}

TEST(PolygonFormFactor, ContourSumsToOneInsideACube) {
    // The six faces of a unit cube seen from the floor: 4 x 0.200043776 + 0.199824896.
    const double f =
        polygon_form_factor(lower(0, 1, 0, 1), up, upper(0, 1, 0, 1, 1), down) + 4 * perpendicular_rectangles(1, 1, 1);
    EXPECT_NEAR(f, 1.0, 1e-8);
}

TEST(PolygonFormFactor, ThinSliversFarBelowRoundingFinish) {
    // Two facets of chair legs from a generated office (0.4 apart, nearly back to back). The
    // contour rule's tolerance, scaled by their tiny area and factor, fell below rounding and
    // Gauss-Kronrod halved every interval to depth 40: the call never returned. It must now
    // agree with the point-to-polygon kernel integrated over the first facet (each clipped to
    // the other's front: both are one-sided), and be reciprocal.
    const Poly a = {{2.54734, 0, 1.828208}, {2.55659, 0.43, 1.820564}, {2.55659, 0, 1.820564}};
    const Poly b = {{2.181753, 0, 1.680932}, {2.181753, 0.43, 1.680932}, {2.192998, 0.43, 1.685121}};
    const auto normal = [](const Poly& p) { return glm::normalize(glm::cross(p[1] - p[0], p[2] - p[0])); };
    const double area_a = 0.5 * glm::length(glm::cross(a[1] - a[0], a[2] - a[0]));
    const double area_b = 0.5 * glm::length(glm::cross(b[1] - b[0], b[2] - b[0]));
    const double fab = polygon_form_factor(a, normal(a), b, normal(b), 1e-8);
    const double fba = polygon_form_factor(b, normal(b), a, normal(a), 1e-8);
    std::vector<glm::dvec3> ac, bc;
    ASSERT_TRUE(clip_to_front(a, b[0], normal(b), 0.0, ac));
    ASSERT_TRUE(clip_to_front(b, a[0], normal(a), 0.0, bc));
    std::vector<AreaSample> q;
    polygon_quadrature(ac, 16, 8, q);
    double kernel = 0.0;
    for (const auto& p : q) kernel += p.weight * point_polygon_form_factor(p.point, normal(a), bc);
    kernel /= area_a;
    EXPECT_TRUE(std::isfinite(fab));
    EXPECT_GE(fab, 0.0);
    // F is about 5e-12 (only slivers face each other); the contour rule's tolerance is relative
    // to max(F estimate, 1e-6), so the errors are absolute: 1.5e-15 and 3e-18 measured.
    EXPECT_GT(kernel, 1e-12);
    EXPECT_NEAR(fab, kernel, 1e-14) << fab << " " << kernel;
    EXPECT_NEAR(area_a * fab, area_b * fba, 1e-16);
}

TEST(PolygonFormFactor, AWallRisingAStripAboveTheFloorsPlaneKeepsItsStrip) {
    // A unit wall x = 0 facing +x whose top edge rises h above the floor's plane: only the
    // strip 0 <= z <= h sees the floor, the shared-edge case from an h-high strip, so
    // F = h F(h x 1 -> 1 x 1). Strips far thinner than the tolerance (a corner grazing the
    // other's plane) are dropped; thin strips above it keep their value.
    for (const double h : {1e-4, 1e-2, 0.5}) {
        const Poly wall = {{0, 0, h - 1}, {0, 1, h - 1}, {0, 1, h}, {0, 0, h}};
        const double f = polygon_form_factor(wall, east, lower(0, 1, 0, 1), up, 1e-10);
        EXPECT_LT(rel(f, h * perpendicular_rectangles(1, h, 1)), 1e-8) << h << ": " << f;
    }
    // At the ray-cast method's tolerance, 1e-6, a strip below 1e-9 of the wall is dropped
    // (F = 0, not h / 2; the clip's rounding alone removes only strips below 1e-12 of the
    // size); one above it is kept, and a strip this thin sees the floor as its edge does,
    // F -> h F(0 x 1 -> 1 x 1), taken at 1e-6.
    const auto strip = [](double h) {
        const Poly wall = {{0, 0, h - 1}, {0, 1, h - 1}, {0, 1, h}, {0, 0, h}};
        return polygon_form_factor(wall, east, lower(0, 1, 0, 1), up, 1e-6);
    };
    EXPECT_EQ(strip(1e-10), 0.0);
    EXPECT_LT(rel(strip(1e-8), 1e-8 * perpendicular_rectangles(1, 1e-6, 1)), 1e-5) << strip(1e-8);
}

TEST(PolygonFormFactor, SeparatedProductRuleEqualsThePlainDoubleSum) {
    // separated_form_factor pads its receiver points to blocks of four and works in blocks of
    // 64 (vectorised, AVX2 where the CPU has it): compare with the plain double loop of the
    // kernel cos t_x cos t_y / (pi r^4) for point counts that fill no block exactly.
    const Poly a = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
    const Poly b = {{0.2, 0.1, 2}, {0.2, 1.3, 2.4}, {1.1, 1.3, 2.4}, {1.1, 0.1, 2}};
    const glm::dvec3 na(0, 0, 1), nb = glm::normalize(glm::cross(b[1] - b[0], b[3] - b[0]));  // towards a
    const double area_b = glm::length(glm::cross(b[1] - b[0], b[3] - b[0]));
    for (const int n_from : {1, 3, 5}) {
        for (const int n_to : {1, 2, 3, 5, 9}) {  // 1, 4, 9, 25, 81 points: 81 spans two blocks
            std::vector<AreaSample> from, to;
            polygon_quadrature(a, 1, n_from, from);
            polygon_quadrature(b, 1, n_to, to);
            for (auto& y : to) y.weight /= area_b;  // fractions of the area (a's is 1)
            double plain = 0.0;
            for (const auto& x : from)
                for (const auto& y : to) {
                    const glm::dvec3 d = y.point - x.point;
                    const double r2 = glm::dot(d, d);
                    plain += x.weight * y.weight * glm::dot(na, d) * -glm::dot(nb, d) / (r2 * r2);
                }
            plain *= area_b / std::numbers::pi;
            const double got = separated_form_factor(from, na, to, area_b, nb);
            EXPECT_GT(plain, 0.01);
            EXPECT_NEAR(got, plain, 1e-14 * plain) << n_from << " x " << n_to;
        }
    }
}
