// SPDX-License-Identifier: MIT
#include "solver/two_pass/caustic_map.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <stdexcept>

#include <tbb/parallel_for.h>
#include <glm/geometric.hpp>
#include <nanoflann.hpp>

#include "solver/optics/fresnel.h"

namespace bounce {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr std::size_t kBlock = 4096;  // photons per random stream and task

/// A cosine-weighted direction about the unit normal n (pdf cos / pi): Malley's method.
glm::dvec3 cosine_direction(const glm::dvec3& n, double u1, double u2) {
    const double r = std::sqrt(u1), phi = 2 * kPi * u2;
    const glm::dvec3 a = std::abs(n.x) > 0.9 ? glm::dvec3(0, 1, 0) : glm::dvec3(1, 0, 0);
    const glm::dvec3 t = glm::normalize(glm::cross(a, n)), b = glm::cross(n, t);
    return glm::normalize(r * std::cos(phi) * t + r * std::sin(phi) * b + std::sqrt(std::max(0.0, 1 - u1)) * n);
}

/// A point uniform by area on a convex patch (its fan triangles chosen by area) from u in [0,1)^3.
glm::dvec3 point_on(const Patch& p, double u0, double u1, double u2) {
    double pick = u0 * p.area;
    int k = 1;
    for (; k + 2 < p.vertex_count; ++k) {
        const double a = 0.5 * glm::length(glm::cross(p.vertices[std::size_t(k)] - p.vertices[0],
                                                      p.vertices[std::size_t(k + 1)] - p.vertices[0]));
        if (pick < a) break;
        pick -= a;
    }
    const double su = std::sqrt(u1);
    return (1 - su) * p.vertices[0] + su * (1 - u2) * p.vertices[std::size_t(k)] +
           su * u2 * p.vertices[std::size_t(k + 1)];
}

struct PhotonCloud {
    const std::vector<CausticPhoton>* photons = nullptr;
    std::size_t kdtree_get_point_count() const { return photons->size(); }
    double kdtree_get_pt(std::size_t i, std::size_t d) const { return (*photons)[i].position[int(d)]; }
    template <class Box>
    bool kdtree_get_bbox(Box&) const {
        return false;
    }
};

using KdTree =
    nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, PhotonCloud>, PhotonCloud, 3, std::size_t>;

}  // namespace

std::optional<CausticPhoton> trace_caustic_photon(const PatchSceneTracer& tracer, glm::dvec3 o, glm::dvec3 d, Rgb power,
                                                  const std::function<double()>& uniform, int max_bounces,
                                                  bool* meets_specular) {
    const double eps = tracer.epsilon();
    bool through_specular = false, diverging = true;
    if (meets_specular) *meets_specular = false;
    for (int bounce = 0; bounce <= max_bounces; ++bounce) {
        const auto hit = tracer.trace(o, d);
        if (hit.missed()) return std::nullopt;
        if (hit.kind == PatchSceneTracer::Hit::Kind::patch) {
            // Stored only after a mirror or glass, and only on a front: a back face absorbs.
            if (through_specular && glm::dot(hit.normal, d) < 0)
                return CausticPhoton{hit.position, hit.normal, power, hit.index, diverging};
            return std::nullopt;
        }
        if (!through_specular && meets_specular) *meets_specular = true;
        through_specular = true;
        const Material& m = tracer.material(hit);
        const double cos_i = -glm::dot(d, hit.normal);
        if (m.kind == MaterialKind::mirror) {
            if (!(cos_i > 0)) return std::nullopt;  // the back of a mirror absorbs
            power = power * m.specular;
            d = glm::normalize(reflect(d, hit.normal));
            o = hit.position + eps * hit.normal;
            if (hit.kind != PatchSceneTracer::Hit::Kind::sphere) diverging = false;
        } else {
            const bool entering = cos_i > 0;
            const glm::dvec3 facing = entering ? hit.normal : -hit.normal;
            const double n1 = entering ? 1.0 : m.ior, n2 = entering ? m.ior : 1.0;
            const double F = fresnel_dielectric(std::abs(cos_i), n1, n2);
            const auto refracted = refract(d, facing, n1, n2);
            if (!refracted || uniform() < F) {
                d = glm::normalize(reflect(d, facing));
                o = hit.position + eps * facing;
                // Inside a sphere its wall is concave: only the outside of one spreads light.
                if (hit.kind != PatchSceneTracer::Hit::Kind::sphere || !entering) diverging = false;
            } else {
                diverging = false;
                d = *refracted;
                o = hit.position - eps * facing;
                if (entering) power = power * m.specular;
            }
        }
        if (!(power.max() > 0)) return std::nullopt;
    }
    return std::nullopt;
}

struct CausticMap::Tree {
    PhotonCloud cloud;
    KdTree index;
    explicit Tree(const std::vector<CausticPhoton>& p)
        : cloud{&p}, index(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(16)) {
        index.buildIndex();
    }
};

CausticMap::CausticMap(const PatchMesh& mesh, const PatchSceneTracer& tracer, const CausticOptions& options,
                       const std::atomic<bool>* stop, const std::vector<Rgb>* exitance)
    : m_patches(mesh.size()) {
    const auto& P = mesh.patches();
    if (exitance && exitance->size() != P.size())
        throw std::invalid_argument("caustic map: exitance and mesh differ in size");
    // What leaves each patch per unit area: its emission, or the radiosity given.
    auto leaving = [&](std::size_t p) { return exitance ? (*exitance)[p] : P[p].emission; };
    m_radius = options.radius > 0 ? options.radius : 0.02 * tracer.diagonal();
    m_nearest = options.nearest;
    // Emitters by power, summed over channels.
    std::vector<int> emitters;
    std::vector<double> cumulative;
    double total = 0;
    for (std::size_t p = 0; p < P.size(); ++p) {
        const Rgb power = leaving(p) * P[p].area;
        m_emitted_power += power;
        if (power.sum() > 0) {
            total += power.sum();
            emitters.push_back(int(p));
            cumulative.push_back(total);
        }
    }
    m_emitted = emitters.empty() ? 0 : options.photons;
    if (m_emitted == 0) return;
    const double eps = tracer.epsilon();
    const std::size_t blocks = (m_emitted + kBlock - 1) / kBlock;
    std::vector<std::vector<CausticPhoton>> stored(blocks);
    std::vector<std::size_t> specular_first(blocks, 0);
    tbb::parallel_for(std::size_t(0), blocks, [&](std::size_t b) {
        if (stop && stop->load(std::memory_order_relaxed)) return;
        std::seed_seq seq{std::uint32_t(options.seed), std::uint32_t(options.seed >> 32), std::uint32_t(b),
                          std::uint32_t(b >> 32), 0x70u /* 'p' */};
        std::mt19937_64 engine(seq);
        const std::function<double()> uniform = [&] { return double(engine() >> 11) * 0x1.0p-53; };
        const std::size_t end = std::min(m_emitted, (b + 1) * kBlock);
        for (std::size_t k = b * kBlock; k < end; ++k) {
            const double pick = uniform() * total;
            const std::size_t e = std::min<std::size_t>(
                std::size_t(std::upper_bound(cumulative.begin(), cumulative.end(), pick) - cumulative.begin()),
                emitters.size() - 1);
            const Patch& source = P[std::size_t(emitters[e])];
            const Rgb out = leaving(std::size_t(emitters[e]));
            // Power: E A / (N q) per channel with q = (E A).sum() / total, the emitter's share.
            const Rgb power = out * (total / (out.sum() * double(m_emitted)));
            const glm::dvec3 o = point_on(source, uniform(), uniform(), uniform()) + eps * source.normal;
            const glm::dvec3 d = cosine_direction(source.normal, uniform(), uniform());
            bool first_specular = false;
            if (auto photon = trace_caustic_photon(tracer, o, d, power, uniform, options.max_bounces, &first_specular))
                stored[b].push_back(*photon);
            specular_first[b] += first_specular ? 1 : 0;
        }
    });
    std::size_t first = 0;
    for (std::size_t b = 0; b < blocks; ++b) {
        m_photons.insert(m_photons.end(), stored[b].begin(), stored[b].end());
        first += specular_first[b];
    }
    m_specular_first = double(first) / double(m_emitted);
    if (!m_photons.empty()) m_tree = std::make_unique<Tree>(m_photons);
}

CausticMap::CausticMap(std::vector<CausticPhoton> photons, double radius, std::size_t patches, std::size_t nearest)
    : m_photons(std::move(photons)), m_patches(patches), m_radius(radius), m_nearest(nearest) {
    if (!(radius > 0)) throw std::invalid_argument("caustic map: radius must be > 0");
    if (!m_photons.empty()) m_tree = std::make_unique<Tree>(m_photons);
}

CausticMap::~CausticMap() = default;

Rgb CausticMap::radiance(const glm::dvec3& x, const glm::dvec3& n, const Rgb& rho) const {
    return rho * irradiance(x, n) * (1.0 / kPi);
}

Rgb CausticMap::irradiance(const glm::dvec3& x, const glm::dvec3& n, double* radius) const {
    if (radius) *radius = m_radius;
    if (!m_tree) return {};
    const double query[3] = {x.x, x.y, x.z};
    double r = m_radius;
    // Every photon within the largest radius; when more than `nearest`, the radius shrinks to
    // the nearest-th of them, found by a partial sort (the tree's own k-nearest search keeps
    // its list sorted by insertion, several times slower at k = 64).
    thread_local std::vector<std::pair<std::size_t, double>> found;
    found.clear();
    // Dense caustics hold the nearest photons well inside the largest radius: a search a
    // quarter as wide (a sixteenth of the photons to sort) finds them there first.
    if (m_nearest > 0) {
        m_tree->index.radiusSearch(query, r * r / 16, found, nanoflann::SearchParams(32, 0.0, false));
        if (found.size() < m_nearest) found.clear();
    }
    if (found.empty()) m_tree->index.radiusSearch(query, r * r, found, nanoflann::SearchParams(32, 0.0, false));
    if (m_nearest > 0 && found.size() > m_nearest) {
        const auto kth = found.begin() + std::ptrdiff_t(m_nearest - 1);
        std::nth_element(found.begin(), kth, found.end(),
                         [](const auto& a, const auto& b) { return a.second < b.second; });
        r = std::sqrt(kth->second);
        found.resize(m_nearest);
    }
    if (radius) *radius = r;
    if (!(r > 0)) return {};
    Rgb sum;
    for (const auto& [i, d2] : found) {
        const CausticPhoton& ph = m_photons[i];
        if (glm::dot(ph.normal, n) < 0.9) continue;
        sum += ph.power * (1.0 - std::sqrt(d2) / r);
    }
    // Cone filter k = 1: the disc's weights integrate to (1 - 2/3) pi r^2.
    return sum * (1.0 / ((1.0 / 3.0) * kPi * r * r));
}

std::vector<Rgb> CausticMap::power_per_patch() const {
    std::vector<Rgb> out(m_patches);
    for (const auto& ph : m_photons) out[std::size_t(ph.patch)] += ph.power;
    return out;
}

}  // namespace bounce
