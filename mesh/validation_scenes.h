// SPDX-License-Identifier: MIT
// The validation cases with known answers, as scenes built in code: plate pairs, coaxial
// disks, closed boxes.
#pragma once

#include <vector>

#include <glm/vec3.hpp>

#include "mesh/scene.h"

#include <cmath>
#include <numbers>

namespace bounce {

/// Two directly opposed a x b rectangles at distance c: the lower (z = 0) faces up, the upper
/// faces down. Surface 0 is the lower one.
inline Scene parallel_pair(double a, double b, double c, Rgb rho = Rgb::gray(0.5)) {
    Scene s;
    s.name = "parallel pair";
    s.materials = {{"m", rho, Rgb()}, {"lamp", Rgb(), Rgb::gray(1.0)}};
    s.surfaces.push_back({{{0, 0, 0}, {a, 0, 0}, {a, b, 0}, {0, b, 0}}, 1, "lower", {"test", 0}});
    s.surfaces.push_back({{{0, 0, c}, {0, b, c}, {a, b, c}, {a, 0, c}}, 0, "upper", {"test", 0}});
    return s;
}

/// Rectangle 1 (w x l, in z = 0, facing +z) and rectangle 2 (h x l, in x = 0, facing +x)
/// sharing the edge along y from 0 to l.
inline Scene perpendicular_pair(double h, double w, double l) {
    Scene s;
    s.name = "perpendicular pair";
    s.materials = {{"m", Rgb::gray(0.5), Rgb()}, {"lamp", Rgb(), Rgb::gray(1.0)}};
    s.surfaces.push_back({{{0, 0, 0}, {w, 0, 0}, {w, l, 0}, {0, l, 0}}, 1, "one", {"test", 0}});
    s.surfaces.push_back({{{0, 0, 0}, {0, l, 0}, {0, l, h}, {0, 0, h}}, 0, "two", {"test", 0}});
    return s;
}

/// Coaxial parallel disks as regular n-gons of the disks' areas (the shape error is
/// O(1/n^2) and area-matched): the emitter (radius r1, z = 0, facing +z) is surface 0, the
/// receiver (radius r2, z = h, facing -z) surface 1.
inline Scene coaxial_disks_scene(double r1, double r2, double h, int n = 96) {
    Scene s;
    s.name = "coaxial disks";
    s.materials = {{"m", Rgb::gray(0.5), Rgb()}, {"lamp", Rgb(), Rgb::gray(1.0)}};
    const double pi = std::numbers::pi, stretch = std::sqrt(2 * pi / (n * std::sin(2 * pi / n)));
    std::vector<glm::dvec3> lower, upper;
    for (int k = 0; k < n; ++k) {
        const double t = 2 * pi * k / n;
        lower.emplace_back(r1 * stretch * std::cos(t), r1 * stretch * std::sin(t), 0.0);
        upper.emplace_back(r2 * stretch * std::cos(-t), r2 * stretch * std::sin(-t), h);
    }
    s.surfaces.push_back({lower, 1, "emitter", {"coaxial disks", 0}});
    s.surfaces.push_back({upper, 0, "receiver", {"coaxial disks", 0}});
    return s;
}

/// A receiving plane z = 0 ([-2,3]^2, rho 0.5, facing up, surface 0) under a unit square lamp at
/// z = 1 ([0,1]^2, E = (3, 2, 1), facing down, reflecting nothing, surface 1); material 2 is
/// black, for blockers. The light at a point of the plane is 0.5 E F(dA -> lamp) exactly.
inline Scene lamp_over_plane() {
    Scene s;
    s.name = "lamp over plane";
    s.materials = {{"plane", Rgb::gray(0.5), Rgb()}, {"lamp", Rgb(), Rgb(3, 2, 1)}, {"black", Rgb(), Rgb()}};
    s.surfaces.push_back({{{-2, -2, 0}, {3, -2, 0}, {3, 3, 0}, {-2, 3, 0}}, 0, "plane", {"test", 0}});
    s.surfaces.push_back({{{0, 0, 1}, {0, 1, 1}, {1, 1, 1}, {1, 0, 1}}, 1, "lamp", {"test", 0}});
    return s;
}

/// A closed box [0,sx]x[0,sy]x[0,sz] facing inwards, every wall with material 0.
inline Scene closed_box(glm::dvec3 size, Material m) {
    Scene s;
    s.name = "closed box";
    s.materials = {m};
    const double x = size.x, y = size.y, z = size.z;
    const std::vector<std::vector<glm::dvec3>> faces = {
        {{0, 0, 0}, {x, 0, 0}, {x, y, 0}, {0, y, 0}},  // z = 0, facing +z
        {{0, 0, z}, {0, y, z}, {x, y, z}, {x, 0, z}},  // z = sz, facing -z
        {{0, 0, 0}, {0, y, 0}, {0, y, z}, {0, 0, z}},  // x = 0, facing +x
        {{x, 0, 0}, {x, 0, z}, {x, y, z}, {x, y, 0}},  // x = sx, facing -x
        {{0, 0, 0}, {0, 0, z}, {x, 0, z}, {x, 0, 0}},  // y = 0, facing +y
        {{0, y, 0}, {x, y, 0}, {x, y, z}, {0, y, z}},  // y = sy, facing -y
    };
    for (const auto& f : faces) s.surfaces.push_back({f, 0, "wall", {"test", 0}});
    return s;
}

/// The furnace with a floating block: a closed 2 m box [0,2]^3 (walls facing in, surfaces 0-5
/// as closed_box's) with a block [0.6,1.4]^2 x [0.5,1.3] floating in it (faces facing out,
/// surfaces 6-11), every face emitting 1 and reflecting 0.9: B = E / (1 - rho) = 10 on every
/// patch, whatever blocks what. `lid` false leaves out the box's face at z = 2, an opening
/// (the block's surfaces are then 5-10).
inline Scene floating_block_furnace(bool lid = true) {
    Scene s = closed_box({2, 2, 2}, {"w", Rgb::gray(0.9), Rgb::gray(1)});
    s.name = "furnace with a floating block";
    if (!lid) s.surfaces.erase(s.surfaces.begin() + 1);  // the face at z = 2
    const double x0 = 0.6, x1 = 1.4, y0 = 0.6, y1 = 1.4, z0 = 0.5, z1 = 1.3;
    const std::vector<std::vector<glm::dvec3>> block = {
        {{x0, y0, z1}, {x1, y0, z1}, {x1, y1, z1}, {x0, y1, z1}},  // top, facing +z
        {{x0, y0, z0}, {x0, y1, z0}, {x1, y1, z0}, {x1, y0, z0}},  // bottom, facing -z
        {{x0, y0, z0}, {x1, y0, z0}, {x1, y0, z1}, {x0, y0, z1}},  // facing -y
        {{x0, y1, z0}, {x0, y1, z1}, {x1, y1, z1}, {x1, y1, z0}},  // facing +y
        {{x0, y0, z0}, {x0, y0, z1}, {x0, y1, z1}, {x0, y1, z0}},  // facing -x
        {{x1, y0, z0}, {x1, y1, z0}, {x1, y1, z1}, {x1, y0, z1}},  // facing +x
    };
    for (const auto& f : block) s.surfaces.push_back({f, 0, "block", {"test", 0}});
    return s;
}

/// A closed room [-3,3] x [0,2.5] x [-2,2] (y up, walls facing in, rho 0.7) with a grey block
/// (rho 0.5) on the floor and a 0.6 x 0.6 lamp (E = 10, facing down) hung `gap` below the ceiling
/// (its back towards it), its footprint [-1.07,-0.47] x [-0.17,0.43]: the common way of modelling
/// a ceiling light. Surfaces: 0-5 the room (4 the ceiling), 6-11 the block, 12 the lamp. Covered
/// regions are left for the caller to find (find_covered_regions).
inline Scene hung_lamp_room(double gap) {
    Scene s;
    s.name = "hung lamp room";
    s.materials = {{"white", Rgb::gray(0.7), Rgb()}, {"grey", Rgb::gray(0.5), Rgb()}, {"lamp", Rgb(), Rgb::gray(10)}};
    const std::vector<std::vector<glm::dvec3>> room = {
        {{-3, 0, -2}, {-3, 0, 2}, {3, 0, 2}, {3, 0, -2}},          // floor, facing +y
        {{-3, 2.5, -2}, {3, 2.5, -2}, {3, 2.5, 2}, {-3, 2.5, 2}},  // ceiling, facing -y
        {{-3, 0, -2}, {3, 0, -2}, {3, 2.5, -2}, {-3, 2.5, -2}},    // z = -2, facing +z
        {{-3, 0, 2}, {-3, 2.5, 2}, {3, 2.5, 2}, {3, 0, 2}},        // z = 2, facing -z
        {{-3, 0, -2}, {-3, 2.5, -2}, {-3, 2.5, 2}, {-3, 0, 2}},    // x = -3, facing +x
        {{3, 0, -2}, {3, 0, 2}, {3, 2.5, 2}, {3, 2.5, -2}},        // x = 3, facing -x
    };
    // Ceiling as surface 4, as the header says.
    const int order[] = {0, 2, 3, 4, 1, 5};
    for (const int k : order) s.surfaces.push_back({room[std::size_t(k)], 0, k == 1 ? "ceiling" : "room", {"test", 0}});
    // The block [0.4,1.6] x [0,0.8] x [0.1,0.9], faces counter-clockwise seen from outside.
    const double x0 = 0.4, x1 = 1.6, y1 = 0.8, z0 = 0.1, z1 = 0.9;
    const std::vector<std::vector<glm::dvec3>> block = {
        {{x0, y1, z0}, {x0, y1, z1}, {x1, y1, z1}, {x1, y1, z0}},  // top
        {{x0, 0, z0}, {x1, 0, z0}, {x1, 0, z1}, {x0, 0, z1}},      // bottom
        {{x0, 0, z0}, {x0, y1, z0}, {x1, y1, z0}, {x1, 0, z0}},    // z0 side, facing -z
        {{x0, 0, z1}, {x1, 0, z1}, {x1, y1, z1}, {x0, y1, z1}},    // z1 side, facing +z
        {{x0, 0, z0}, {x0, 0, z1}, {x0, y1, z1}, {x0, y1, z0}},    // x0 side, facing -x
        {{x1, 0, z0}, {x1, y1, z0}, {x1, y1, z1}, {x1, 0, z1}},    // x1 side, facing +x
    };
    for (const auto& f : block) s.surfaces.push_back({f, 1, "block", {"test", 0}});
    const double y = 2.5 - gap;
    s.surfaces.push_back(
        {{{-1.07, y, -0.17}, {-0.47, y, -0.17}, {-0.47, y, 0.43}, {-1.07, y, 0.43}}, 2, "lamp", {"test", 0}});
    return s;
}

}  // namespace bounce
