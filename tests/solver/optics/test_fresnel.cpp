// SPDX-License-Identifier: MIT
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "solver/optics/fresnel.h"

using namespace bounce;
using V = glm::dvec3;

TEST(Fresnel, NormalIncidenceAndGrazingAndBrewster) {
    for (const double n : {1.33, 1.5, 2.4}) {
        const double r0 = std::pow((n - 1) / (n + 1), 2);
        EXPECT_NEAR(fresnel_dielectric(1.0, 1.0, n), r0, 1e-15);
        EXPECT_NEAR(fresnel_dielectric(1.0, n, 1.0), r0, 1e-15);   // the same from inside
        EXPECT_NEAR(fresnel_dielectric(0.0, 1.0, n), 1.0, 1e-12);  // grazing
        // At Brewster's angle, tan theta_B = n, p-polarised light is not reflected at all: F = r_s^2 / 2.
        const double theta_b = std::atan(n), ci = std::cos(theta_b);
        const double ct = std::cos(std::numbers::pi / 2 - theta_b);
        const double rs = (ci - n * ct) / (ci + n * ct);
        EXPECT_NEAR(fresnel_dielectric(ci, 1.0, n), 0.5 * rs * rs, 1e-14);
    }
}

TEST(Fresnel, TotalInternalReflectionPastTheCriticalAngle) {
    const double n = 1.5, critical = std::asin(1.0 / n);  // 41.8 degrees
    EXPECT_DOUBLE_EQ(fresnel_dielectric(std::cos(critical + 1e-6), n, 1.0), 1.0);
    EXPECT_DOUBLE_EQ(fresnel_dielectric(std::cos(std::numbers::pi / 4), n, 1.0), 1.0);
    EXPECT_LT(fresnel_dielectric(std::cos(critical - 1e-3), n, 1.0), 1.0);
    const V d = glm::normalize(V(1, 0, -1));  // 45 degrees, inside glass, towards the surface z = 0 (normal -z inside)
    EXPECT_FALSE(refract(d, V(0, 0, 1), n, 1.0));
    // Below the critical angle Snell's law holds.
    const V d2 = glm::normalize(V(std::sin(0.5), 0, -std::cos(0.5)));
    const auto t = refract(d2, V(0, 0, 1), 1.0, n);
    ASSERT_TRUE(t);
    EXPECT_NEAR(std::sqrt(t->x * t->x + t->y * t->y), std::sin(0.5) / n, 1e-14);
    EXPECT_LT(t->z, 0);
    EXPECT_NEAR(glm::length(reflect(d2, V(0, 0, 1)) - V(d2.x, d2.y, -d2.z)), 0.0, 1e-15);
}
