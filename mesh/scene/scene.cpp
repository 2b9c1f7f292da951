// SPDX-License-Identifier: MIT
#include "mesh/scene/scene.h"

#include <cmath>
#include <sstream>

#include "mesh/scene/input_error.h"

namespace bounce {

std::string Rgb::to_string() const {
    std::ostringstream s;
    s << "(" << r << ", " << g << ", " << b << ")";
    return s.str();
}

std::string to_string(MaterialKind kind) {
    switch (kind) {
        case MaterialKind::diffuse:
            return "diffuse";
        case MaterialKind::mirror:
            return "mirror";
        case MaterialKind::glass:
            return "glass";
    }
    return "?";
}

std::string SourceLocation::to_string() const {
    if (line > 0) return file + ":" + std::to_string(line);
    return file;
}

std::string describe(const SourceLocation& where, const std::string& object) {
    const std::string w = where.to_string();
    if (object.empty() || w.find(object) != std::string::npos) return w;
    return w + " (" + object + ")";
}

std::string length_text(double value, const std::string& units) {
    std::ostringstream s;
    s.precision(3);
    s << value << " " << (units.empty() ? "scene units" : units);
    return s.str();
}

void Scene::validate() const {
    for (const auto& m : materials) {
        if (m.is_specular()) {
            const std::string what = m.kind == MaterialKind::mirror ? "mirror reflectance" : "glass transmittance";
            for (int c = 0; c < 3; ++c)
                if (!std::isfinite(m.specular[c]) || m.specular[c] < 0.0 || m.specular[c] > 1.0)
                    throw InputError("material '" + m.name + "': " + what + " out of range, got " +
                                     m.specular.to_string() + " (expected 0 to 1 per channel)");
            if (m.kind == MaterialKind::glass && !(std::isfinite(m.ior) && m.ior >= 1.0))
                throw InputError("material '" + m.name + "': index of refraction out of range, got " +
                                 number_text(m.ior) + " (expected >= 1)");
            if (m.emission.max() != 0.0 || m.emission.min() != 0.0)
                throw InputError("material '" + m.name + "': a " + to_string(m.kind) + " does not emit, got emission " +
                                 m.emission.to_string());
            continue;
        }
        for (int c = 0; c < 3; ++c) {
            const double rho = m.reflectance[c], e = m.emission[c];
            if (!std::isfinite(rho) || rho < 0.0 || rho > 1.0)
                throw InputError("material '" + m.name + "': reflectance out of range, got " +
                                 m.reflectance.to_string() + " (expected 0 to 1 per channel)");
            if (!std::isfinite(e) || e < 0.0)
                throw InputError("material '" + m.name + "': emission out of range, got " + m.emission.to_string() +
                                 " (expected finite and >= 0 per channel)");
        }
    }
    for (const auto& s : surfaces) {
        for (const auto& v : s.vertices)
            if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z))
                throw InputError(s.where.to_string() + ": face has a NaN or infinite coordinate");
        if (s.material < 0 || s.material >= int(materials.size()))
            throw InputError(s.where.to_string() + ": face has no valid material");
        if (materials[std::size_t(s.material)].is_specular())
            throw InputError(s.where.to_string() + ": a diffuse surface has the " +
                             to_string(materials[std::size_t(s.material)].kind) + " material '" +
                             materials[std::size_t(s.material)].name + "'");
    }
    for (const auto& s : specular_surfaces) {
        for (const auto& v : s.vertices)
            if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z))
                throw InputError(s.where.to_string() + ": face has a NaN or infinite coordinate");
        if (s.material < 0 || s.material >= int(materials.size()) || !materials[std::size_t(s.material)].is_specular())
            throw InputError(s.where.to_string() + ": a specular face has no mirror or glass material");
    }
    for (const auto& s : spheres) {
        const std::string where = describe(s.where, s.object);
        if (!s.transform.is_invertible())
            throw InputError(where + ": sphere transform is singular (flattens the sphere)");
        const auto& m = s.transform.matrix();
        for (int c = 0; c < 4; ++c)
            for (int r = 0; r < 4; ++r)
                if (!std::isfinite(m[c][r])) throw InputError(where + ": sphere transform is not finite");
        if (s.material < 0 || s.material >= int(materials.size()) || !materials[std::size_t(s.material)].is_specular())
            throw InputError(where + ": a sphere must be of a mirror or glass material");
    }
}

}  // namespace bounce
