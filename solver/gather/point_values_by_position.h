// SPDX-License-Identifier: MIT
// Gathered point values looked up by position within a surface, for carrying the vertices of
// one conforming mesh over to the next (display refinement of hierarchical and patch solutions).
#pragma once

#include <cmath>
#include <cstdint>
#include <functional>
#include <unordered_map>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "mesh/scene/rgb.h"

namespace bounce {

/// Values by position within a surface, to carry the gathered vertices of one conforming
/// mesh over to the next: the mesh welds points closer than 1e-9 of the scene's diagonal, so a
/// point may come back a few bits off when another leaf first names it.
template <class Value>
class PointMap {
public:
    explicit PointMap(double weld) : m_weld(weld), m_cell(1024 * weld) {}
    struct Entry {
        glm::dvec3 at;
        Value value;
    };
    void add(int surface, const Entry& e) { m_grid[key(surface, e.at)].push_back(e); }
    /// Replaces the value of the point at x (within the weld); false when there is none.
    bool set(int surface, const glm::dvec3& x, const Value& value) {
        const Value* found = find(surface, x);
        if (!found) return false;
        *const_cast<Value*>(found) = value;  // find's entry lives in m_grid, which this object owns
        return true;
    }
    const Value* find(int surface, const glm::dvec3& x) const {
        const Key k = key(surface, x);
        for (std::int64_t dx = -1; dx <= 1; ++dx)
            for (std::int64_t dy = -1; dy <= 1; ++dy)
                for (std::int64_t dz = -1; dz <= 1; ++dz) {
                    const auto it = m_grid.find({k.surface, k.x + dx, k.y + dy, k.z + dz});
                    if (it == m_grid.end()) continue;
                    for (const Entry& e : it->second)
                        if (glm::length(e.at - x) <= m_weld) return &e.value;
                }
        return nullptr;
    }

private:
    struct Key {
        int surface;
        std::int64_t x, y, z;
        bool operator==(const Key&) const = default;
    };
    struct Hash {
        std::size_t operator()(const Key& k) const {
            std::size_t h = std::hash<std::int64_t>{}(k.x);
            h = h * 0x9E3779B97F4A7C15ull ^ std::hash<std::int64_t>{}(k.y);
            h = h * 0x9E3779B97F4A7C15ull ^ std::hash<std::int64_t>{}(k.z);
            return h * 0x9E3779B97F4A7C15ull ^ std::hash<int>{}(k.surface);
        }
    };
    Key key(int surface, const glm::dvec3& x) const {
        return {surface, std::int64_t(std::floor(x.x / m_cell)), std::int64_t(std::floor(x.y / m_cell)),
                std::int64_t(std::floor(x.z / m_cell))};
    }
    double m_weld, m_cell;
    std::unordered_map<Key, std::vector<Entry>, Hash> m_grid;
};

/// Gathered point values (radiosity) by position.
using PointValues = PointMap<Rgb>;

}  // namespace bounce
