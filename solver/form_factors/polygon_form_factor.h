// SPDX-License-Identifier: MIT
#pragma once

#include <span>
#include <vector>

#include <glm/vec3.hpp>

#include "mesh/scene/polygon.h"
#include "solver/form_factors/patch_sampling.h"

namespace bounce {

/// Exact, unoccluded form factor between two planar convex polygons (vertices counter-clockwise
/// seen from the front, unit normals towards the front): the fraction of the power leaving
/// `from` diffusely that arrives at `to`,
///
///     F = 1/A_from  int_from int_to  cos t_from cos t_to / (pi r^2)  dA_to dA_from.
///
/// Each polygon is first clipped to the other's front half-space (only that part exchanges
/// power), so pairs that straddle each other's planes are exact too; coplanar pairs give 0.
/// Well-separated pairs integrate the exact point-to-polygon kernel (Lambert) over the smaller
/// polygon with Gauss-Legendre orders n = 1, 2, 3, ... until two successive orders agree within
/// `rel_tol` (View3D's stopping rule, Walton 2002); near, touching and edge-sharing pairs use the
/// contour integral (contour_form_factor). The result is within about rel_tol of the exact value
/// (1e-9 asked: 1e-12 measured on the tables of shared/VALIDATION.md), and within an absolute
/// max(1e-3 rel_tol, 1e-24) more: a clipped part that small a share of `from` (a sliver where
/// a corner grazes the other's plane) is dropped, since F <= min(A_from', A_to') / A_from.
double polygon_form_factor(std::span<const glm::dvec3> from, const glm::dvec3& n_from, std::span<const glm::dvec3> to,
                           const glm::dvec3& n_to, double rel_tol = 1e-10);

/// The contour-integral form (Stokes' theorem twice; Sparrow 1963, Schroeder and Hanrahan 1993):
///
///     A_from F = 1/(2 pi) sum_p sum_q (e_p . e_q) int_0^1 int_0^1 ln |x_p(s) - y_q(t)| dt ds
///
/// over the edges p of `from` and q of `to`. The inner integral is in closed form,
///     int ln(L sqrt((t - t0)^2 + d^2)) dt = ln L + [u ln(u^2 + d^2) - 2u + 2d atan(u/d)] / 2,
/// finite even on the segment itself (d = 0: u ln u^2 -> 0), so shared and collinear edges,
/// whose log singularity sits exactly there, are integrated analytically; the outer integral is
/// adaptive Gauss-Kronrod (7-15), split where the outer edge passes the inner edge's ends.
/// Both polygons must lie in front of each other (no clipping here).
double contour_form_factor(std::span<const glm::dvec3> from, std::span<const glm::dvec3> to, double rel_tol = 1e-11);

/// The Bernstein ellipse parameter of the form-factor kernel over a polygon of circumradius
/// `radius` seen from at least `gap` away: the kernel is analytic within the ellipse
/// rho = g + sqrt(g^2 + 1), g = gap / radius, so the n-point Gauss-Legendre rule per side errs
/// like rho^(-2n) and order n reaches a relative tolerance tol once rho^(2n) >= 1 / tol (Davis
/// and Rabinowitz, "Methods of numerical integration", 4.6). 0 when gap <= 0 (the rule does
/// not apply).
double separation_rho(double gap, double radius);

/// F_from->to of a well-separated pair, both polygons in front of each other, from
/// quadrature points whose weights are fractions of each polygon's area (patch_quadrature):
/// the product rule of the point-to-point kernel, F = A_to sum w_x w_y cos t_x cos t_y /
/// (pi r^2). It needs no trigonometry, so at the orders separation_rho predicts it is several
/// times faster than integrating the point-to-polygon kernel, to the same tolerance.
double separated_form_factor(std::span<const AreaSample> from, const glm::dvec3& n_from, std::span<const AreaSample> to,
                             double area_to, const glm::dvec3& n_to);

/// Composite Gauss-Legendre points over a convex polygon: the unit square cut into
/// cells x cells squares with n x n points each, mapped bilinearly onto a quad, or by the
/// collapsed square (Duffy) onto each triangle of the fan from p[0]; weights are areas (they
/// sum to the polygon's area).
void polygon_quadrature(std::span<const glm::dvec3> p, int cells, int n, std::vector<AreaSample>& out);

/// The part of convex `p` in front of the plane through o with normal n (vertices within tol
/// of the plane count as on it); false when nothing of positive area is left.
bool clip_to_front(std::span<const glm::dvec3> p, const glm::dvec3& o, const glm::dvec3& n, double tol,
                   std::vector<glm::dvec3>& out);

}  // namespace bounce
