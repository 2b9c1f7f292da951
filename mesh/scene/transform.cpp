// SPDX-License-Identifier: MIT
#include "mesh/scene/transform.h"

#include <cmath>

#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/matrix.hpp>

namespace bounce {

Transform::Transform(const glm::dmat4& m) : m_m(m) {
    const glm::dmat3 lin(m);
    m_normal = is_invertible() ? glm::transpose(glm::inverse(lin)) : glm::dmat3(0.0);
}

Transform Transform::translate(const glm::dvec3& t) { return Transform(glm::translate(glm::dmat4(1.0), t)); }
Transform Transform::scale(const glm::dvec3& s) { return Transform(glm::scale(glm::dmat4(1.0), s)); }
Transform Transform::rotate(double degrees, const glm::dvec3& axis) {
    return Transform(glm::rotate(glm::dmat4(1.0), glm::radians(degrees), glm::normalize(axis)));
}

glm::dvec3 Transform::point(const glm::dvec3& p) const { return glm::dvec3(m_m * glm::dvec4(p, 1.0)); }

glm::dvec3 Transform::vector(const glm::dvec3& v) const { return glm::dmat3(m_m) * v; }

// The inverse of the linear part is the transpose of the stored inverse transpose.
glm::dvec3 Transform::inverse_vector(const glm::dvec3& v) const { return glm::transpose(m_normal) * v; }

glm::dvec3 Transform::inverse_point(const glm::dvec3& p) const { return inverse_vector(p - glm::dvec3(m_m[3])); }

glm::dvec3 Transform::normal(const glm::dvec3& n) const { return glm::normalize(m_normal * n); }

bool Transform::flips_orientation() const { return glm::determinant(glm::dmat3(m_m)) < 0.0; }

bool Transform::is_invertible() const {
    const double d = glm::determinant(glm::dmat3(m_m));
    return std::isfinite(d) && std::abs(d) > 1e-300;
}

}  // namespace bounce
