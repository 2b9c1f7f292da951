// SPDX-License-Identifier: MIT
// Ideal specular scattering: mirror reflection, refraction by Snell's law and the exact Fresnel
// reflectance of a dielectric for unpolarised light (Born and Wolf, Principles of Optics, 1.5;
// pbrt-v4 section 9.3). Shared by the path tracer and the eye pass.
#pragma once

#include <algorithm>
#include <cmath>
#include <optional>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

namespace bounce {

/// The direction d reflected about the unit normal n (either side): d - 2 (d . n) n.
inline glm::dvec3 reflect(const glm::dvec3& d, const glm::dvec3& n) { return d - 2.0 * glm::dot(d, n) * n; }

/// Fresnel reflectance of a smooth dielectric interface for unpolarised light, the mean of
/// the s- and p-polarised reflectances:
///     r_s = (n1 cos_i - n2 cos_t) / (n1 cos_i + n2 cos_t),  r_p = (n2 cos_i - n1 cos_t) / (n2 cos_i + n1 cos_t),
///     F = (r_s^2 + r_p^2) / 2,
/// for light arriving in the medium of index n1 at cos_i in [0, 1] to the normal; sin_t =
/// (n1 / n2) sin_i. Past the critical angle (sin_t >= 1, only when n1 > n2) all is reflected:
/// total internal reflection, F = 1. At normal incidence F = ((n1 - n2) / (n1 + n2))^2.
inline double fresnel_dielectric(double cos_i, double n1, double n2) {
    cos_i = std::clamp(cos_i, 0.0, 1.0);
    const double sin_t = n1 / n2 * std::sqrt(std::max(0.0, 1.0 - cos_i * cos_i));
    if (sin_t >= 1.0) return 1.0;
    const double cos_t = std::sqrt(std::max(0.0, 1.0 - sin_t * sin_t));
    const double rs = (n1 * cos_i - n2 * cos_t) / (n1 * cos_i + n2 * cos_t);
    const double rp = (n2 * cos_i - n1 * cos_t) / (n2 * cos_i + n1 * cos_t);
    return 0.5 * (rs * rs + rp * rp);
}

/// The unit direction d refracted through an interface with unit normal n on the side d comes
/// from (d . n < 0), from index n1 into n2 (Snell: n1 sin_i = n2 sin_t); nothing past the
/// critical angle.
inline std::optional<glm::dvec3> refract(const glm::dvec3& d, const glm::dvec3& n, double n1, double n2) {
    const double eta = n1 / n2;
    const double cos_i = -glm::dot(d, n);
    const double sin2_t = eta * eta * std::max(0.0, 1.0 - cos_i * cos_i);
    if (sin2_t >= 1.0) return std::nullopt;
    const double cos_t = std::sqrt(1.0 - sin2_t);
    return glm::normalize(eta * d + (eta * cos_i - cos_t) * n);
}

}  // namespace bounce
