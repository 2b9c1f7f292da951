// SPDX-License-Identifier: MIT
#include "solver/form_factors/polygon_form_factor.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <vector>

#include <glm/geometric.hpp>

#include "mesh/scene/polygon.h"
#include "solver/form_factors/point_polygon_form_factor.h"

namespace bounce {
namespace {

constexpr double kPi = std::numbers::pi;

/// Gauss-Kronrod 7-15 on [-1, 1] (Piessens et al., QUADPACK qk15): Kronrod nodes and weights,
/// and the 7-point Gauss weights at the odd Kronrod nodes.
constexpr double kXgk[8] = {0.991455371120812639206854697526329, 0.949107912342758524526189684047851,
                            0.864864423359769072789712788640926, 0.741531185599394439863864773280788,
                            0.586087235467691130294144845693013, 0.405845151377397166906606412076961,
                            0.207784955007898467600689403773245, 0.0};
constexpr double kWgk[8] = {0.022935322010529224963732008058970, 0.063092092629978553290700663189204,
                            0.104790010322250183839876322541518, 0.140653259715525918745189590510238,
                            0.169004726639267902826583426598550, 0.190350578064785409913256402421014,
                            0.204432940075298892414161999234649, 0.209482141084727828012999174891714};
constexpr double kWg[4] = {0.129484966168869693270611432679082, 0.279705391489276667901467771423780,
                           0.381830050505118944950369775488975, 0.417959183673469387755102040816327};

/// int_a^b f by adaptive Gauss-Kronrod 7-15: an interval is accepted when |K15 - G7| <= tol,
/// otherwise halved, each half with half the tolerance. Two floors keep a tolerance below
/// rounding from recursing without end (a thin sliver's tolerance can be 1e-14 of an integrand
/// of size 1, and every level then halves everywhere, 2^40 intervals): an interval is also
/// accepted when the difference is at the rounding level of the integral of |f| over it, and
/// at most `budget` intervals are split in one call.
template <class F>
double adaptive_gk(const F& f, double a, double b, double tol, int& budget, int depth = 0) {
    const double c = 0.5 * (a + b), h = 0.5 * (b - a);
    const double fc = f(c);
    double k = kWgk[7] * fc, g = kWg[3] * fc, kabs = kWgk[7] * std::abs(fc);
    for (int i = 0; i < 7; ++i) {
        const double f1 = f(c - h * kXgk[i]), f2 = f(c + h * kXgk[i]);
        k += kWgk[i] * (f1 + f2);
        kabs += kWgk[i] * (std::abs(f1) + std::abs(f2));
        if (i % 2 == 1) g += kWg[i / 2] * (f1 + f2);
    }
    k *= h;
    g *= h;
    kabs *= std::abs(h);
    const double diff = std::abs(k - g);
    if (diff <= tol || diff <= 1e-13 * kabs || depth >= 40 || h < 1e-15 || budget <= 0) return k;
    --budget;
    return adaptive_gk(f, a, c, 0.5 * tol, budget, depth + 1) + adaptive_gk(f, c, b, 0.5 * tol, budget, depth + 1);
}

/// int (u ln(u^2 + d^2) - 2u + 2d atan(u/d)) is the antiderivative of ln(u^2 + d^2); 0 at u = 0.
double log_antiderivative(double u, double d) {
    if (u == 0.0) return 0.0;
    const double t = u * std::log(u * u + d * d) - 2.0 * u;
    return d > 0.0 ? t + 2.0 * d * std::atan(u / d) : t;
}

/// Unit normal of a planar polygon (Newell's method), towards the side it runs
/// counter-clockwise from.
glm::dvec3 polygon_normal(std::span<const glm::dvec3> p) {
    glm::dvec3 n(0.0);
    for (std::size_t k = 0; k < p.size(); ++k) n += glm::cross(p[k], p[(k + 1) % p.size()]);
    const double l = glm::length(n);
    return l > 0 ? n / l : n;
}

glm::dvec3 centroid(std::span<const glm::dvec3> p) {
    // Area centroid of the fan from p[0].
    glm::dvec3 c(0.0);
    double w = 0.0;
    for (std::size_t k = 1; k + 1 < p.size(); ++k) {
        const double a = glm::length(glm::cross(p[k] - p[0], p[k + 1] - p[0]));
        c += a * (p[0] + p[k] + p[k + 1]) / 3.0;
        w += a;
    }
    return w > 0 ? c / w : p[0];
}

double radius(std::span<const glm::dvec3> p, const glm::dvec3& c) {
    double r = 0.0;
    for (const auto& v : p) r = std::max(r, glm::length(v - c));
    return r;
}

/// The part of convex `p` at height >= 0 above the plane (o, n); vertices within `tol` of the
/// plane count as on it. Returns false when nothing of positive area is left.
bool clip_front(std::span<const glm::dvec3> p, const glm::dvec3& o, const glm::dvec3& n, double tol,
                std::vector<glm::dvec3>& out) {
    out.clear();
    bool any_below = false, any_above = false;
    for (const auto& v : p) {
        const double h = glm::dot(n, v - o);
        any_below |= h < -tol;
        any_above |= h > tol;
    }
    if (!any_above) return false;
    if (!any_below) {
        out.assign(p.begin(), p.end());
        return true;
    }
    for (std::size_t k = 0; k < p.size(); ++k) {
        const glm::dvec3 &a = p[k], &b = p[(k + 1) % p.size()];
        const double ha = glm::dot(n, a - o), hb = glm::dot(n, b - o);
        if (ha >= 0) out.push_back(a);
        if ((ha >= 0) != (hb >= 0)) out.push_back(a + (ha / (ha - hb)) * (b - a));
    }
    return out.size() >= 3;
}

/// (1/A_r) int_r F(dA -> s) dA with n x n points on r: F_{r -> s}.
double area_gauss(std::span<const glm::dvec3> r, const glm::dvec3& n_r, std::span<const glm::dvec3> s, int n) {
    thread_local std::vector<AreaSample> q;
    polygon_quadrature(r, 1, n, q);
    double f = 0.0, a = 0.0;
    for (const auto& x : q) {
        f += x.weight * point_polygon_form_factor(x.point, n_r, s);
        a += x.weight;
    }
    return a > 0 ? f / a : 0.0;
}

}  // namespace

double separation_rho(double gap, double radius) {
    if (!(gap > 0.0) || !(radius > 0.0)) return 0.0;
    const double g = gap / radius;
    return g + std::sqrt(g * g + 1.0);
}

namespace {

/// The product rule's double sum (separated_form_factor): the receiver points in plain arrays,
/// padded to blocks of four (zero weight), so that each block of the inner loop, a difference,
/// three dot products and one division, is one vector operation: this loop is most of a
/// closed room's form-factor time.
[[gnu::always_inline]] inline double separated_sum(std::span<const AreaSample> from, const glm::dvec3& n_from,
                                                   std::span<const AreaSample> to, const glm::dvec3& n_to) {
    constexpr std::size_t kBlock = 64, kLanes = 4;
    alignas(32) std::array<double, kBlock> yx, yy, yz, yw;
    std::array<double, kLanes> acc{};
    for (std::size_t first = 0; first < to.size(); first += kBlock) {
        const std::size_t m = std::min(kBlock, to.size() - first);
        const std::size_t padded = (m + kLanes - 1) / kLanes * kLanes;
        for (std::size_t k = 0; k < m; ++k) {
            const AreaSample& y = to[first + k];
            yx[k] = y.point.x;
            yy[k] = y.point.y;
            yz[k] = y.point.z;
            yw[k] = y.weight;
        }
        for (std::size_t k = m; k < padded; ++k) {  // the last point again, weight 0: finite, adds nothing
            yx[k] = yx[m - 1];
            yy[k] = yy[m - 1];
            yz[k] = yz[m - 1];
            yw[k] = 0.0;
        }
        for (const auto& x : from) {
            const double wx = x.weight;
            for (std::size_t k = 0; k < padded; k += kLanes)
                for (std::size_t l = 0; l < kLanes; ++l) {
                    const double dx = yx[k + l] - x.point.x, dy = yy[k + l] - x.point.y, dz = yz[k + l] - x.point.z;
                    const double d2 = dx * dx + dy * dy + dz * dz;
                    const double cos_from = n_from.x * dx + n_from.y * dy + n_from.z * dz;
                    const double cos_to = n_to.x * dx + n_to.y * dy + n_to.z * dz;
                    acc[l] -= (wx * yw[k + l]) * (cos_from * cos_to) / (d2 * d2);
                }
        }
    }
    return (acc[0] + acc[1]) + (acc[2] + acc[3]);
}

#if defined(__GNUC__) && defined(__x86_64__)
// The same loop compiled for AVX2 and FMA, chosen at run time where the CPU has them: four
// kernels per instruction instead of two, in the one portable binary.
[[gnu::target("avx2,fma")]] double separated_sum_avx2(std::span<const AreaSample> from, const glm::dvec3& n_from,
                                                      std::span<const AreaSample> to, const glm::dvec3& n_to) {
    return separated_sum(from, n_from, to, n_to);
}
const bool kHasAvx2 = [] {
    __builtin_cpu_init();  // static initialisers may run before the library's own
    return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
}();
#endif

}  // namespace

double separated_form_factor(std::span<const AreaSample> from, const glm::dvec3& n_from, std::span<const AreaSample> to,
                             double area_to, const glm::dvec3& n_to) {
#if defined(__GNUC__) && defined(__x86_64__)
    const double sum = kHasAvx2 ? separated_sum_avx2(from, n_from, to, n_to) : separated_sum(from, n_from, to, n_to);
#else
    const double sum = separated_sum(from, n_from, to, n_to);
#endif
    return std::max(0.0, sum * area_to / kPi);
}

void polygon_quadrature(std::span<const glm::dvec3> p, int cells, int n, std::vector<AreaSample>& out) {
    out.clear();
    thread_local std::vector<double> x, w;
    gauss_legendre(n, x, w);
    const double h = 1.0 / cells;
    for (int cv = 0; cv < cells; ++cv)
        for (int cu = 0; cu < cells; ++cu)
            for (int b = 0; b < n; ++b)
                for (int a = 0; a < n; ++a) {
                    const double u = (cu + x[a]) * h, v = (cv + x[b]) * h, wt = w[a] * w[b] * h * h;
                    if (p.size() == 4) {
                        // Bilinear map of the unit square, weighted by its Jacobian.
                        const auto& c = p;
                        const glm::dvec3 du = (1 - v) * (c[1] - c[0]) + v * (c[2] - c[3]);
                        const glm::dvec3 dv = (1 - u) * (c[3] - c[0]) + u * (c[2] - c[1]);
                        out.push_back(
                            {(1 - u) * (1 - v) * c[0] + u * (1 - v) * c[1] + u * v * c[2] + (1 - u) * v * c[3],
                             wt * glm::length(glm::cross(du, dv))});
                        continue;
                    }
                    // Collapsed square (Duffy) on each triangle of the fan from p[0].
                    for (std::size_t k = 1; k + 1 < p.size(); ++k) {
                        const glm::dvec3 &c0 = p[0], &c1 = p[k], &c2 = p[k + 1];
                        const double twice_area = glm::length(glm::cross(c1 - c0, c2 - c0));
                        out.push_back({(1 - u) * c0 + u * (1 - v) * c1 + u * v * c2, wt * u * twice_area});
                    }
                }
}

bool clip_to_front(std::span<const glm::dvec3> p, const glm::dvec3& o, const glm::dvec3& n, double tol,
                   std::vector<glm::dvec3>& out) {
    return clip_front(p, o, n, tol, out);
}

double contour_form_factor(std::span<const glm::dvec3> from, std::span<const glm::dvec3> to, double rel_tol) {
    const double a_from = polygon_area(from);
    if (a_from <= 0.0 || polygon_area(to) <= 0.0) return 0.0;
    const glm::dvec3 c_from = centroid(from), c_to = centroid(to);
    // ln r - ln r_ref has the same double contour integral (the contours are closed), and is
    // small where the pair is far apart, so the edge sums cancel less.
    const double r_ref = std::max(glm::length(c_to - c_from), 1e-300);
    const double log_ref = std::log(r_ref);
    // The tolerance is relative to an estimate of A_from F (the centre's point factor).
    const double f_est = std::max(point_polygon_form_factor(c_from, polygon_normal(from), to), 1e-6);
    const std::size_t pairs = from.size() * to.size();
    const double total_tol = rel_tol * 2.0 * kPi * a_from * f_est;

    double sum = 0.0;
    std::array<double, 8> cuts;
    for (std::size_t p = 0; p < from.size(); ++p) {
        const glm::dvec3 x0 = from[p], f = from[(p + 1) % from.size()] - x0;
        const double ff = glm::dot(f, f);
        for (std::size_t q = 0; q < to.size(); ++q) {
            const glm::dvec3 y0 = to[q], e = to[(q + 1) % to.size()] - y0;
            const double ee = glm::dot(e, e), fe = glm::dot(f, e);
            if (std::abs(fe) <= 1e-14 * std::sqrt(ff * ee)) continue;  // perpendicular edges add nothing
            const double log_l = 0.5 * std::log(ee);
            // g(s) = int_0^1 ln |x(s) - y(t)| dt - ln r_ref, in closed form (see the header).
            const auto g = [&](double s) {
                const glm::dvec3 w = x0 + s * f - y0;
                const double t0 = glm::dot(w, e) / ee;
                const double d = glm::length(w - t0 * e) / std::sqrt(ee);
                return log_l + 0.5 * (log_antiderivative(1.0 - t0, d) - log_antiderivative(-t0, d)) - log_ref;
            };
            // Split where x(s) passes the ends of the inner edge and where the two lines are
            // closest: the integrand's derivative has its log singularities there.
            int m = 0;
            cuts[m++] = 0.0;
            cuts[m++] = 1.0;
            for (const glm::dvec3& y : {y0, y0 + e}) cuts[m++] = glm::dot(y - x0, f) / ff;
            const double det = ff * ee - fe * fe;
            if (det > 1e-12 * ff * ee) {
                const glm::dvec3 r = x0 - y0;
                cuts[m++] = (fe * glm::dot(e, r) - ee * glm::dot(f, r)) / det;
            }
            for (int k = 0; k < m; ++k) cuts[k] = std::clamp(cuts[k], 0.0, 1.0);
            for (int a = 1; a < m; ++a)  // insertion sort of at most 5 cuts
                for (int b = a; b > 0 && cuts[b - 1] > cuts[b]; --b) std::swap(cuts[b - 1], cuts[b]);
            const double tol = total_tol / (double(pairs) * std::abs(fe));
            double integral = 0.0;
            for (int k = 0; k + 1 < m; ++k) {
                const double len = cuts[k + 1] - cuts[k];
                if (len <= 1e-14) continue;
                int budget = 4096;
                integral += adaptive_gk(g, cuts[k], cuts[k + 1], tol * len, budget);
            }
            sum += fe * integral;
        }
    }
    return std::max(0.0, sum / (2.0 * kPi * a_from));
}

double polygon_form_factor(std::span<const glm::dvec3> from, const glm::dvec3& n_from, std::span<const glm::dvec3> to,
                           const glm::dvec3& n_to, double rel_tol) {
    thread_local std::vector<glm::dvec3> cf, ct;
    const double size = std::sqrt(std::max(polygon_area(from), polygon_area(to)));
    const double tol = 1e-12 * size;  // rounding: a vertex on the other's plane is on it
    // Only the part of each in front of the other exchanges power (both one-sided).
    if (!clip_front(from, to[0], n_to, tol, cf) || !clip_front(to, from[0], n_from, tol, ct)) return 0.0;
    const double a_from = polygon_area(from), a_cf = polygon_area(cf), a_ct = polygon_area(ct);
    // A clipped part this thin (a sliver where a corner grazes the other's plane) carries
    // F <= min(A_cf, A_ct) / A_from, far below the tolerance (F_cf->ct <= 1 and, by
    // reciprocity, A_cf F_cf->ct <= A_ct); its edge sums cancel to rounding, so the contour
    // integral could not reach a tolerance relative to it and would spend its whole budget.
    if (std::min(a_cf, a_ct) <= std::max(1e-3 * rel_tol, 1e-24) * a_from) return 0.0;
    // F_from->to = (A_cf / A_from) F_cf->ct.
    const glm::dvec3 c_f = centroid(cf), c_t = centroid(ct);
    const double r_f = radius(cf, c_f), r_t = radius(ct, c_t);
    const double gap = glm::length(c_t - c_f) - r_f - r_t;  // lower bound on the distance
    const bool f_small = a_cf <= a_ct;
    const double r_small = f_small ? r_f : r_t;
    if (gap > 2.0 * r_small) {
        // Well separated: the point-to-polygon kernel is smooth over the smaller polygon.
        const auto small = f_small ? std::span<const glm::dvec3>(cf) : std::span<const glm::dvec3>(ct);
        const auto large = f_small ? std::span<const glm::dvec3>(ct) : std::span<const glm::dvec3>(cf);
        const glm::dvec3 n_small = f_small ? n_from : n_to;
        const double a_small = f_small ? a_cf : a_ct;
        // Gauss-Legendre converges like rho^(-2n) for a kernel analytic within the Bernstein
        // ellipse rho = g + sqrt(g^2 + 1), g = gap / radius: start one below the order that
        // predicts, and go up until two successive orders agree.
        const double g = gap / r_small, rho = g + std::sqrt(g * g + 1.0);
        const int predicted = int(std::ceil(std::log(1.0 / rel_tol) / (2.0 * std::log(rho))));
        int n = std::clamp(predicted - 1, 1, 8);
        double prev = area_gauss(small, n_small, large, n);
        for (++n; n <= 10; ++n) {
            const double cur = area_gauss(small, n_small, large, n);
            if (std::abs(cur - prev) <= rel_tol * std::abs(cur)) return cur * a_small / a_from;
            prev = cur;
        }
    }
    return contour_form_factor(cf, ct, rel_tol) * a_cf / a_from;
}

}  // namespace bounce
