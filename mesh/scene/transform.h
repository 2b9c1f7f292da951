// SPDX-License-Identifier: MIT
#pragma once

#include <glm/mat3x3.hpp>
#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

namespace bounce {

/// An affine placement T of an object. Points go by T; normals by the inverse transpose of
/// T's linear part, which keeps them perpendicular to the faces under non-uniform scale and
/// shear (a normal n is a covector: n^T v = 0 for tangents v must survive v -> M v).
class Transform {
public:
    Transform() = default;
    explicit Transform(const glm::dmat4& m);

    static Transform translate(const glm::dvec3& t);
    static Transform scale(const glm::dvec3& s);
    /// Rotation by `degrees` about `axis` (right-handed).
    static Transform rotate(double degrees, const glm::dvec3& axis);

    /// Composition: (a * b) applies b first, then a.
    friend Transform operator*(const Transform& a, const Transform& b) { return Transform(a.m_m * b.m_m); }

    glm::dvec3 point(const glm::dvec3& p) const;
    /// A direction (or offset) by the linear part of T: no translation.
    glm::dvec3 vector(const glm::dvec3& v) const;
    /// T^-1 p and the inverse linear part applied to v: a ray taken into the object's own
    /// frame (its parameter t is unchanged when both origin and direction go this way).
    glm::dvec3 inverse_point(const glm::dvec3& p) const;
    glm::dvec3 inverse_vector(const glm::dvec3& v) const;
    /// Transformed unit normal: normalize((M^-1)^T n).
    glm::dvec3 normal(const glm::dvec3& n) const;
    /// A mirroring transform (det < 0) turns counter-clockwise faces clockwise; readers
    /// reverse the vertex order so the front side stays the front.
    bool flips_orientation() const;
    bool is_invertible() const;
    const glm::dmat4& matrix() const { return m_m; }

private:
    glm::dmat4 m_m{1.0};
    glm::dmat3 m_normal{1.0};
};

}  // namespace bounce
