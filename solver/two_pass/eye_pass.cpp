// SPDX-License-Identifier: MIT
#include "solver/two_pass/eye_pass.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>

#include <tbb/parallel_for.h>
#include <glm/geometric.hpp>

#include "solver/optics/fresnel.h"
#include "solver/two_pass/caustic_map.h"
#include "solver/two_pass/patch_scene_tracer.h"

namespace bounce {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr int kRefine = 4;  // a refined pixel's strata per side, per side of the first k x k

/// The mesh vertex at each corner of patch p, in the order of Patch::vertices (the tracer's
/// fan triangles), matched by position: a face of a conforming mesh of display cells also
/// holds points on its edges (where a neighbour is split finer), and its list may start
/// elsewhere. corners[0] < 0 when a corner has no vertex with a value.
std::array<int, 4> patch_corners(const PatchMesh& m, std::size_t p, std::size_t values) {
    std::array<int, 4> corners;
    corners.fill(-1);
    const Patch& patch = m.patches()[p];
    const auto idx = m.patch_vertex_indices(p);
    if (int(idx.size()) < patch.vertex_count) return corners;
    for (int k = 0; k < patch.vertex_count; ++k) {
        const glm::dvec3& corner = patch.vertices[std::size_t(k)];
        double best = std::numeric_limits<double>::infinity();
        for (const int v : idx) {
            if (v < 0 || std::size_t(v) >= values) {
                corners.fill(-1);
                return corners;
            }
            const double d = glm::length(m.vertex_position(std::size_t(v)) - corner);
            if (d < best) {
                best = d;
                corners[std::size_t(k)] = v;
            }
        }
    }
    return corners;
}

/// The caustic estimates made for one pixel's rays, which its other rays reuse where they
/// land within kReuse of the estimate's radius r (on a surface facing the same way): the cone
/// filter of radius r varies little over a tenth of it, and a pixel's rays on a surface far
/// from any caustic, where r is the bound, would otherwise search the same photons again.
class CausticReuse {
public:
    static constexpr double kReuse = 0.1;
    const Rgb* find(const glm::dvec3& x, const glm::dvec3& n) const {
        for (std::size_t k = 0; k < m_count; ++k) {
            const Entry& e = m_entries[k];
            if (glm::dot(e.normal, n) > 0.999 && glm::length(x - e.position) < kReuse * e.radius) return &e.irradiance;
        }
        return nullptr;
    }
    void add(const glm::dvec3& x, const glm::dvec3& n, double radius, const Rgb& irradiance) {
        m_entries[m_next] = {x, n, radius, irradiance};
        m_next = (m_next + 1) % m_entries.size();
        m_count = std::min(m_count + 1, m_entries.size());
    }
    void clear() { m_count = m_next = 0; }

private:
    struct Entry {
        glm::dvec3 position, normal;
        double radius;
        Rgb irradiance;
    };
    std::array<Entry, 4> m_entries{};
    std::size_t m_count = 0, m_next = 0;
};

}  // namespace

struct EyePass::Impl {
    const Scene& scene;
    const PatchMesh& mesh;
    PatchSceneTracer tracer;
    std::vector<Rgb> vertex_radiosity, patch_radiosity;
    std::vector<std::array<int, 4>> corners;  // per patch: its vertices' indices; corners[p][0] < 0: none
    const CausticMap* caustics = nullptr;

    Impl(const Scene& s, const PatchMesh& m, std::vector<Rgb> vb, std::vector<Rgb> pb, const CausticMap* c)
        : scene(s),
          mesh(m),
          tracer(s, m),
          vertex_radiosity(std::move(vb)),
          patch_radiosity(std::move(pb)),
          caustics(c) {
        corners.resize(m.size());
        for (std::size_t p = 0; p < m.size(); ++p) corners[p] = patch_corners(m, p, vertex_radiosity.size());
    }

    /// B at a point of a patch: the point data interpolated over the fan triangle the ray hit
    /// (as a renderer's Gouraud shading does), or the patch's value.
    Rgb radiosity_at(const PatchSceneTracer::Hit& hit) const {
        const auto& c = corners[std::size_t(hit.index)];
        if (c[0] < 0) return patch_radiosity[std::size_t(hit.index)];
        return vertex_radiosity[std::size_t(c[0])] * (1.0 - hit.u - hit.v) +
               vertex_radiosity[std::size_t(c[std::size_t(hit.fan)])] * hit.u +
               vertex_radiosity[std::size_t(c[std::size_t(hit.fan + 1)])] * hit.v;
    }

    /// Whitted's recursion: what arrives along o + t d, seen with weight `weight` (the largest
    /// channel of the product of the reflectances and transmittances so far).
    /// The caustic irradiance at a diffuse hit, reused from `reuse` when one of its estimates
    /// lies near enough.
    Rgb caustic_irradiance(const PatchSceneTracer::Hit& hit, CausticReuse* reuse) const {
        if (reuse)
            if (const Rgb* known = reuse->find(hit.position, hit.normal)) return *known;
        double r = 0;
        const Rgb E = caustics->irradiance(hit.position, hit.normal, &r);
        if (reuse) reuse->add(hit.position, hit.normal, r, E);
        return E;
    }

    Rgb trace(const glm::dvec3& o, const glm::dvec3& d, int depth, double weight, const EyePassOptions& opt,
              CausticReuse* reuse) const {
        const auto hit = tracer.trace(o, d);
        if (hit.missed()) return {};
        if (hit.kind == PatchSceneTracer::Hit::Kind::patch) {
            if (glm::dot(hit.normal, d) >= 0) return {};  // the back of a one-sided face
            Rgb L = radiosity_at(hit) * (1.0 / kPi);
            if (caustics)
                L += mesh.patches()[std::size_t(hit.index)].reflectance * caustic_irradiance(hit, reuse) * (1.0 / kPi);
            return L;
        }
        if (depth >= opt.max_depth) return {};
        const Material& m = tracer.material(hit);
        const double eps = tracer.epsilon();
        const double cos_i = -glm::dot(d, hit.normal);
        if (m.kind == MaterialKind::mirror) {
            if (!(cos_i > 0)) return {};
            const double w = weight * m.specular.max();
            if (w < opt.min_weight) return {};
            return m.specular * trace(hit.position + eps * hit.normal, glm::normalize(reflect(d, hit.normal)),
                                      depth + 1, w, opt, reuse);
        }
        const bool entering = cos_i > 0;
        const glm::dvec3 facing = entering ? hit.normal : -hit.normal;
        const double n1 = entering ? 1.0 : m.ior, n2 = entering ? m.ior : 1.0;
        const auto refracted = refract(d, facing, n1, n2);
        const double F = refracted ? fresnel_dielectric(std::abs(cos_i), n1, n2) : 1.0;
        Rgb L;
        if (weight * F >= opt.min_weight)
            L += F * trace(hit.position + eps * facing, glm::normalize(reflect(d, facing)), depth + 1, weight * F, opt,
                           reuse);
        if (refracted) {
            const Rgb tint = entering ? m.specular : Rgb::gray(1.0);
            const double w = weight * (1 - F) * tint.max();
            if (w >= opt.min_weight)
                L += (1 - F) * tint * trace(hit.position - eps * facing, *refracted, depth + 1, w, opt, reuse);
        }
        return L;
    }
};

EyePass::EyePass(const Scene& scene, const PatchMesh& mesh, std::vector<Rgb> vertex_radiosity,
                 std::vector<Rgb> patch_radiosity, const CausticMap* caustics)
    : m_impl(std::make_unique<Impl>(scene, mesh, std::move(vertex_radiosity), std::move(patch_radiosity), caustics)) {}

EyePass::~EyePass() = default;

Rgb EyePass::radiance(const glm::dvec3& origin, const glm::dvec3& direction, const EyePassOptions& options) const {
    return m_impl->trace(origin, glm::normalize(direction), 0, 1.0, options, nullptr);
}

EyeImage EyePass::render(const PinholeCamera& camera, const EyePassOptions& options,
                         const std::function<void(std::size_t, std::size_t)>& progress,
                         const std::atomic<bool>* stop) const {
    EyeImage image;
    image.width = options.width;
    image.height = options.height;
    image.pixels.assign(std::size_t(options.width) * std::size_t(options.height), Rgb());
    // The view's frame: w forward, u right, v up; the image plane at distance 1 spans
    // tan(fov / 2) up and down, and as much across as the aspect ratio gives.
    const glm::dvec3 w = glm::normalize(camera.target - camera.position);
    const glm::dvec3 u = glm::normalize(glm::cross(w, camera.up));
    const glm::dvec3 v = glm::cross(u, w);
    const double half_h = std::tan(0.5 * camera.vertical_fov * kPi / 180.0);
    const double half_w = half_h * double(options.width) / double(options.height);
    const int k = std::max(1, int(std::ceil(std::sqrt(double(std::max(1, options.samples_per_pixel))))));
    std::atomic<std::size_t> done{0};
    tbb::parallel_for(0, options.height, [&](int row) {
        if (stop && stop->load(std::memory_order_relaxed)) return;
        std::seed_seq seq{std::uint32_t(options.seed), std::uint32_t(options.seed >> 32), std::uint32_t(row), 0x65u};
        std::mt19937_64 engine(seq);
        auto uniform = [&] { return double(engine() >> 11) * 0x1.0p-53; };
        CausticReuse reuse;
        // Jittered n x n strata over the pixel, box filter: their sum, and the least and
        // greatest luminance of one ray.
        auto strata = [&](int col, int n, double& lo, double& hi) {
            Rgb sum;
            for (int s = 0; s < n * n; ++s) {
                const double px = (col + (s % n + uniform()) / n) / options.width;
                const double py = (row + (s / n + uniform()) / n) / options.height;
                const glm::dvec3 d = w + (2 * px - 1) * half_w * u + (1 - 2 * py) * half_h * v;
                const Rgb L = m_impl->trace(camera.position, glm::normalize(d), 0, 1.0, options, &reuse);
                lo = std::min(lo, L.luminance());
                hi = std::max(hi, L.luminance());
                sum += L;
            }
            return sum;
        };
        for (int col = 0; col < options.width; ++col) {
            reuse.clear();
            double lo = std::numeric_limits<double>::infinity(), hi = 0;
            Rgb sum = strata(col, k, lo, hi);
            int rays = k * k;
            // Mitchell's contrast test (1987): a pixel whose rays disagree this much holds an
            // edge (a lamp's, whose radiance is a hundredfold the walls', or a silhouette) that
            // k x k rays place too coarsely; it gets kRefine^2 times as many.
            if (options.refine_contrast > 0 && hi > 0 && (hi - lo) > options.refine_contrast * (hi + lo)) {
                sum += strata(col, k * kRefine, lo, hi);
                rays += k * kRefine * k * kRefine;
            }
            image.pixels[std::size_t(row) * std::size_t(options.width) + std::size_t(col)] = sum * (1.0 / rays);
        }
        const std::size_t d = ++done;
        if (progress) progress(d, std::size_t(options.height));
    });
    image.rows_done = done.load();
    return image;
}

}  // namespace bounce
