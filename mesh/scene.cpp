// SPDX-License-Identifier: MIT
#include "mesh/scene.h"

#include <cmath>
#include <sstream>

#include "mesh/input_error.h"

namespace bounce {

std::string Rgb::to_string() const {
    std::ostringstream s;
    s << "(" << r << ", " << g << ", " << b << ")";
    return s.str();
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
        for (int c = 0; c < 3; ++c) {
            const double rho = m.reflectance[c], e = m.emission[c];
            if (!std::isfinite(rho) || rho < 0.0 || rho > 1.0)
                throw InputError("material '" + m.name + "': reflectance out of range, got " +
                                 m.reflectance.to_string() + " (expected 0 to 1 per channel)");
            if (!std::isfinite(e) || e < 0.0)
                throw InputError("material '" + m.name + "': emission out of range, got " +
                                 m.emission.to_string() + " (expected finite and >= 0 per channel)");
        }
    }
    for (const auto& s : surfaces) {
        for (const auto& v : s.vertices)
            if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z))
                throw InputError(s.where.to_string() + ": face has a NaN or infinite coordinate");
        if (s.material < 0 || s.material >= int(materials.size()))
            throw InputError(s.where.to_string() + ": face has no valid material");
    }
}

}  // namespace bounce
