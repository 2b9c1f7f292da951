// SPDX-License-Identifier: MIT
// bounce-office: writes a large open-plan office as a Wavefront OBJ + MTL for bounce, at a
// chosen number of triangles (within a few triangles of the request).
//
//   bounce-office --triangles 100000 --seed 1 -o office.obj     (also writes office.mtl)
//
// The room (metres, y up) is closed: floor, ceiling with emitting light panels, a window wall
// (z = depth) whose panes emit daylight, a door wall (z = 0) and two side walls lined with
// bookcases. Rows of desk pairs (rounded tops, cylinder legs, pedestal, monitor, keyboard,
// chairs) fill the middle; cabinets with plants stand under the windows. The count grows by
// realistic means: finer tessellation of the curved parts (cylinders, rounded corners, rounded
// edges) with the size, more desks, and books on the shelves to reach the exact count.
//
// Every face is a triangle, wound counter-clockwise seen from its front (outward on furniture,
// into the room on walls). Faces that rest on another surface (a leg's foot on the floor, a
// book's bottom on its shelf, a bookcase's back on the wall) are left out: no light reaches
// them. Parts touch but never cross. The same seed gives the same file.
#include <algorithm>
#include <array>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <stdexcept>
#include <string>
#include <system_error>
#include <vector>

#include <CLI/CLI.hpp>
#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

namespace {

constexpr double kPi = 3.14159265358979323846;

// Random numbers: splitmix64, one independent stream per item (seed, kind, index), so adding a
// desk does not reshuffle the books, and the file does not depend on the standard library.
struct Rng {
    std::uint64_t state;
    Rng(std::uint64_t seed, std::uint64_t kind, std::uint64_t index)
        : state(seed * 0x9E3779B97F4A7C15ull ^ (kind + 1) * 0xBF58476D1CE4E5B9ull ^
                (index + 1) * 0x94D049BB133111EBull) {
        next();
    }
    std::uint64_t next() {
        std::uint64_t z = (state += 0x9E3779B97F4A7C15ull);
        z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
        z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
        return z ^ (z >> 31);
    }
    double uniform(double a, double b) { return a + (b - a) * double(next() >> 11) * 0x1.0p-53; }
    int below(int n) { return int(next() % std::uint64_t(n)); }
};

// Materials: reflectance Kd in [0,1], emitted radiosity Ke (W/m^2 per channel).
struct MaterialDef {
    const char* name;
    glm::dvec3 kd, ke;
};
enum Mat {
    kWall,
    kCeiling,
    kFloor,
    kWindow,
    kPanel,
    kFrame,
    kDoor,
    kDeskTop,
    kMetal,
    kPedestal,
    kChair,
    kMonitor,
    kKeyboard,
    kShelf,
    kStorageBox,
    kPot,
    kLeaves,
    kMug,
    kBook0
};
constexpr int kBookColours = 8;
const std::vector<MaterialDef>& materials() {
    static const std::vector<MaterialDef> m = {
        {"wall", {0.74, 0.73, 0.69}, {}},
        {"ceiling", {0.82, 0.82, 0.80}, {}},
        {"carpet", {0.22, 0.24, 0.27}, {}},
        {"window_daylight", {0.08, 0.08, 0.08}, {9.0, 10.0, 11.5}},
        {"ceiling_panel", {0.80, 0.80, 0.80}, {12.0, 11.5, 10.5}},
        {"window_frame", {0.80, 0.80, 0.78}, {}},
        {"door", {0.45, 0.30, 0.18}, {}},
        {"desk_laminate", {0.62, 0.50, 0.36}, {}},
        {"metal", {0.50, 0.50, 0.52}, {}},
        {"pedestal", {0.60, 0.60, 0.60}, {}},
        {"chair_fabric", {0.10, 0.15, 0.35}, {}},
        {"monitor", {0.05, 0.05, 0.05}, {}},
        {"keyboard", {0.12, 0.12, 0.12}, {}},
        {"shelf_wood", {0.50, 0.35, 0.20}, {}},
        {"storage_box", {0.80, 0.75, 0.60}, {}},
        {"terracotta", {0.45, 0.22, 0.12}, {}},
        {"leaves", {0.10, 0.32, 0.08}, {}},
        {"mug", {0.85, 0.85, 0.82}, {}},
        {"book_red", {0.55, 0.08, 0.07}, {}},
        {"book_blue", {0.08, 0.15, 0.45}, {}},
        {"book_green", {0.10, 0.35, 0.15}, {}},
        {"book_ochre", {0.70, 0.55, 0.15}, {}},
        {"book_white", {0.85, 0.83, 0.78}, {}},
        {"book_black", {0.06, 0.06, 0.06}, {}},
        {"book_brown", {0.35, 0.20, 0.10}, {}},
        {"book_grey", {0.45, 0.45, 0.47}, {}},
    };
    return m;
}

// A placement: world = origin + R_y(yaw) * local (yaw about +y).
struct Frame {
    glm::dvec3 origin{0.0};
    double yaw = 0.0;
    glm::dvec3 dir(const glm::dvec3& v) const {
        const double c = std::cos(yaw), s = std::sin(yaw);
        return {c * v.x + s * v.z, v.y, -s * v.x + c * v.z};
    }
    glm::dvec3 point(const glm::dvec3& p) const { return origin + dir(p); }
    Frame child(const glm::dvec3& offset, double turn = 0.0) const { return {point(offset), yaw + turn}; }
};

struct Triangle {
    int a, b, c, material;
};
struct Object {
    std::string name;
    std::size_t first_vertex, first_triangle;
};

// The scene as triangles, grouped into objects (one per primitive, so each is convex).
struct Mesh {
    std::vector<glm::dvec3> vertices;
    std::vector<Triangle> triangles;
    std::vector<Object> objects;
    void begin(std::string name) { objects.push_back({std::move(name), vertices.size(), triangles.size()}); }
    int vertex(const glm::dvec3& p) {
        vertices.push_back(p);
        return int(vertices.size()) - 1;
    }
    // Adds a triangle facing `outward` (it is turned round when its winding disagrees).
    void triangle(int a, int b, int c, int m, const glm::dvec3& outward) {
        const glm::dvec3 n = glm::cross(vertices[b] - vertices[a], vertices[c] - vertices[a]);
        if (glm::dot(n, outward) < 0.0) std::swap(b, c);
        triangles.push_back({a, b, c, m});
    }
};

// A horizontal ring of points (x, z), convex and centred on the local origin.
using Ring = std::vector<glm::dvec2>;

Ring rounded_rect(double hx, double hz, double r, int segments) {
    Ring ring;
    if (r <= 0.0 || segments <= 0) return {{hx, -hz}, {hx, hz}, {-hx, hz}, {-hx, -hz}};
    const glm::dvec2 centres[4] = {{hx - r, -hz + r}, {hx - r, hz - r}, {-hx + r, hz - r}, {-hx + r, -hz + r}};
    for (int c = 0; c < 4; ++c)
        for (int i = 0; i <= segments; ++i) {
            const double a = (c - 1) * kPi / 2 + (kPi / 2) * i / segments;
            ring.push_back(centres[c] + r * glm::dvec2(std::cos(a), std::sin(a)));
        }
    return ring;
}

Ring circle(double r, int n) {
    Ring ring;
    for (int i = 0; i < n; ++i) ring.push_back(r * glm::dvec2(std::cos(2 * kPi * i / n), std::sin(2 * kPi * i / n)));
    return ring;
}

// Box sides of a rounded_rect(.., 0, 0) ring, by edge: +x, +z, -x, -z.
enum Side { kPX = 1, kPZ = 2, kNX = 4, kNZ = 8 };

// A loft: rings (same point count, same shape, shrinking or growing) stacked at heights y,
// joined by side triangles, closed by caps. A ring of radius 0 is an apex. skip_sides drops
// side strips by ring edge (bit e: edge e, for boxes the Side bits); caps may be left out
// where the solid rests on or touches something.
struct Level {
    Ring ring;
    double y;
};
void loft(Mesh& mesh, const Frame& f, const std::vector<Level>& levels, int m, bool bottom_cap, bool top_cap,
          unsigned skip_sides = 0) {
    const std::size_t n = levels[0].ring.size();
    std::vector<std::vector<int>> idx(levels.size());
    for (std::size_t l = 0; l < levels.size(); ++l) {
        const Ring& r = levels[l].ring;
        const bool apex = glm::length(r[0]) == 0.0;
        for (std::size_t i = 0; i < (apex ? 1 : n); ++i)
            idx[l].push_back(mesh.vertex(f.point({r[i].x, levels[l].y, r[i].y})));
    }
    for (std::size_t l = 0; l + 1 < levels.size(); ++l)
        for (std::size_t i = 0; i < n; ++i) {
            if (skip_sides & (1u << i)) continue;
            const std::size_t j = (i + 1) % n;
            const glm::dvec2 mid =
                0.25 * (levels[l].ring[i] + levels[l].ring[j] + levels[l + 1].ring[i] + levels[l + 1].ring[j]);
            const glm::dvec3 out = f.dir({mid.x, 0.0, mid.y});
            const auto& lo = idx[l];
            const auto& hi = idx[l + 1];
            if (lo.size() == 1) {
                mesh.triangle(lo[0], hi[i], hi[j], m, out);
            } else if (hi.size() == 1) {
                mesh.triangle(lo[i], lo[j], hi[0], m, out);
            } else {
                mesh.triangle(lo[i], lo[j], hi[j], m, out);
                mesh.triangle(lo[i], hi[j], hi[i], m, out);
            }
        }
    auto cap = [&](std::size_t l, double up) {
        const auto& v = idx[l];
        if (v.size() < 3) return;
        const glm::dvec3 out = f.dir({0.0, up, 0.0});
        if (v.size() == 4) {
            mesh.triangle(v[0], v[1], v[2], m, out);
            mesh.triangle(v[0], v[2], v[3], m, out);
            return;
        }
        const int c = mesh.vertex(f.point({0.0, levels[l].y, 0.0}));  // fan from the centre: no slivers
        for (std::size_t i = 0; i < v.size(); ++i) mesh.triangle(c, v[i], v[(i + 1) % v.size()], m, out);
    };
    if (bottom_cap) cap(0, -1.0);
    if (top_cap) cap(levels.size() - 1, 1.0);
}

// An axis-aligned (in its frame) box centred on x = z = 0, from y0 to y1.
void box(Mesh& mesh, const Frame& f, double hx, double hz, double y0, double y1, int m, bool bottom = false,
         bool top = true, unsigned skip_sides = 0) {
    const Ring r = rounded_rect(hx, hz, 0.0, 0);
    loft(mesh, f, {{r, y0}, {r, y1}}, m, bottom, top, skip_sides);
}

void cylinder(Mesh& mesh, const Frame& f, double r, double y0, double y1, int n, int m, bool bottom, bool top) {
    const Ring c = circle(r, n);
    loft(mesh, f, {{c, y0}, {c, y1}}, m, bottom, top);
}

// A slab with rounded corners (radius rc, `corner` segments each) and rounded top and bottom
// edges (radius e, `edge` segments each; edge = 0: square edges).
void rounded_slab(Mesh& mesh, const Frame& f, double hx, double hz, double rc, double y0, double y1, double e,
                  int corner, int edge, int m, bool bottom) {
    std::vector<Level> levels;
    auto ring = [&](double inset) { return rounded_rect(hx - inset, hz - inset, rc - inset, corner); };
    if (edge <= 0) {
        levels = {{ring(0.0), y0}, {ring(0.0), y1}};
    } else {
        for (int i = 0; i <= edge; ++i) {
            const double a = -kPi / 2 + (kPi / 2) * i / edge;
            levels.push_back({ring(e * (1.0 - std::cos(a))), y0 + e + e * std::sin(a)});
        }
        for (int i = 0; i <= edge; ++i) {
            const double a = (kPi / 2) * i / edge;
            levels.push_back({ring(e * (1.0 - std::cos(a))), y1 - e + e * std::sin(a)});
        }
    }
    loft(mesh, f, levels, m, bottom, true);
}

// How finely curved parts are cut, from the requested size.
struct Detail {
    int cylinder;  // segments around a leg, a pot, a mug
    int corner;    // segments per rounded corner
    int edge;      // segments per rounded edge profile (0: square edges)
};
Detail detail_for(long triangles) {
    const double s = std::cbrt(double(triangles) / 1e4);
    Detail d;
    d.cylinder = std::clamp(int(std::lround(8 * s)), 6, 48);
    d.corner = std::clamp(int(std::lround(d.cylinder / 4.0)), 1, 12);
    d.edge = d.cylinder < 10 ? 0 : std::clamp(int(std::lround(d.cylinder / 8.0)), 1, 6);
    return d;
}

// The room's plan for a number of desk pairs.
constexpr double kHeight = 3.0;  // floor to ceiling
constexpr double kDeskW = 1.6, kDeskD = 0.8, kDeskY = 0.72, kDeskT = 0.03;
constexpr double kPairGap = 0.02;      // between the backs of two facing desks, and desk ends
constexpr double kChairOffset = 0.36;  // chair centre in front of the desk's front edge
constexpr double kBenchPairs = 3;      // desk pairs side by side in one bench
constexpr double kAisleX = 1.5, kAisleZ = 1.2;
constexpr double kCaseW = 0.9, kCaseD = 0.35, kCaseH = 2.0, kCaseGap = 0.01;
constexpr double kWalkway = 1.2;   // between the bookcases and the desks
constexpr double kDoorSide = 1.6;  // between the door wall and the first bench
constexpr double kCabinetD = 0.45, kCabinetH = 0.75, kWindowSide = 1.2;

struct Plan {
    int pairs = 1;
    int cols = 1, rows = 1;  // benches along x, along z
    double width = 0, depth = 0;
    double bench_z = 0;  // depth of a bench with its chairs
};
Plan plan_for(int pairs) {
    Plan p;
    p.pairs = pairs;
    const int benches = (pairs + int(kBenchPairs) - 1) / int(kBenchPairs);
    p.cols = std::max(1, int(std::ceil(std::sqrt(benches * 1.3))));
    p.rows = (benches + p.cols - 1) / p.cols;
    const double bench_len = std::min(pairs, int(kBenchPairs)) * (kDeskW + kPairGap);
    p.bench_z = 2 * kDeskD + kPairGap + 2 * (kChairOffset + 0.35);
    p.width = 2 * (kCaseD + kWalkway) + p.cols * bench_len + (p.cols - 1) * kAisleX;
    p.depth = kDoorSide + p.rows * p.bench_z + (p.rows - 1) * kAisleZ + kWindowSide + kCabinetD;
    p.width = std::max(p.width, 6.0);
    p.depth = std::max(p.depth, 5.0);
    return p;
}

// One cell-tiled wall, floor or ceiling: the rectangle [u0,u1] x [v0,v1] of a plane cut at the
// given breakpoints; each cell takes the material `material_at` its centre.
template <typename ToWorld, typename MaterialAt>
void tiled(Mesh& mesh, std::vector<double> us, std::vector<double> vs, const glm::dvec3& inward, ToWorld to_world,
           MaterialAt material_at) {
    auto clean = [](std::vector<double>& x) {
        std::sort(x.begin(), x.end());
        x.erase(std::unique(x.begin(), x.end(), [](double a, double b) { return std::abs(a - b) < 1e-9; }), x.end());
    };
    clean(us);
    clean(vs);
    std::vector<int> idx(us.size() * vs.size());
    for (std::size_t j = 0; j < vs.size(); ++j)
        for (std::size_t i = 0; i < us.size(); ++i) idx[j * us.size() + i] = mesh.vertex(to_world(us[i], vs[j]));
    for (std::size_t j = 0; j + 1 < vs.size(); ++j)
        for (std::size_t i = 0; i + 1 < us.size(); ++i) {
            const int m = material_at(0.5 * (us[i] + us[i + 1]), 0.5 * (vs[j] + vs[j + 1]));
            const int a = idx[j * us.size() + i], b = idx[j * us.size() + i + 1];
            const int c = idx[(j + 1) * us.size() + i + 1], d = idx[(j + 1) * us.size() + i];
            mesh.triangle(a, b, c, m, inward);
            mesh.triangle(a, c, d, m, inward);
        }
}

struct Rect {
    double u0, u1, v0, v1;
    bool contains(double u, double v) const { return u > u0 && u < u1 && v > v0 && v < v1; }
};

void room(Mesh& mesh, const Plan& p) {
    const double W = p.width, D = p.depth, H = kHeight;
    mesh.begin("room.floor");
    tiled(
        mesh, {0, W}, {0, D}, {0, 1, 0}, [](double u, double v) { return glm::dvec3(u, 0, v); },
        [](double, double) { return int(kFloor); });
    // Ceiling: 1.2 x 0.6 m light panels over the desks, every 2.4 m.
    std::vector<Rect> panels;
    for (double x = 2.4; x + 1.2 <= W - 1.0; x += 2.4)
        for (double z = kDoorSide + 0.6; z + 0.6 <= D - 1.0; z += 2.4) panels.push_back({x, x + 1.2, z, z + 0.6});
    std::vector<double> us = {0, W}, vs = {0, D};
    for (const Rect& r : panels) us.insert(us.end(), {r.u0, r.u1}), vs.insert(vs.end(), {r.v0, r.v1});
    mesh.begin("room.ceiling");
    tiled(
        mesh, us, vs, {0, -1, 0}, [H](double u, double v) { return glm::dvec3(u, H, v); },
        [&panels](double u, double v) {
            for (const Rect& r : panels)
                if (r.contains(u, v)) return int(kPanel);
            return int(kCeiling);
        });
    // Window wall (z = D): windows 1.8 m wide every 2.4 m, sill 0.9 m, head 2.5 m, two panes
    // each in a 6 cm frame.
    const double sill = 0.9, head = 2.5, fr = 0.06;
    std::vector<Rect> frames, panes;
    const int windows = std::max(1, int((W - 0.6) / 2.4));
    const double start = 0.5 * (W - windows * 2.4);
    for (int k = 0; k < windows; ++k) {
        const double x0 = start + k * 2.4 + 0.3, x1 = x0 + 1.8, xm = 0.5 * (x0 + x1);
        frames.push_back({x0, x1, sill, head});
        panes.push_back({x0 + fr, xm - fr / 2, sill + fr, head - fr});
        panes.push_back({xm + fr / 2, x1 - fr, sill + fr, head - fr});
    }
    us = {0, W};
    vs = {0, sill, sill + fr, head - fr, head, H};
    for (const Rect& r : panes) us.insert(us.end(), {r.u0, r.u1, r.u0 - fr, r.u1 + fr});
    mesh.begin("room.window_wall");
    tiled(
        mesh, us, vs, {0, 0, -1}, [D](double u, double v) { return glm::dvec3(u, v, D); },
        [&](double u, double v) {
            for (const Rect& r : panes)
                if (r.contains(u, v)) return int(kWindow);
            for (const Rect& r : frames)
                if (r.contains(u, v)) return int(kFrame);
            return int(kWall);
        });
    // Door wall (z = 0): one door near the corner.
    const Rect door{kCaseD + 0.2, kCaseD + 1.2, 0.0, 2.1};
    mesh.begin("room.door_wall");
    tiled(
        mesh, {0, door.u0, door.u1, W}, {0, door.v1, H}, {0, 0, 1},
        [](double u, double v) { return glm::dvec3(u, v, 0); },
        [&door](double u, double v) { return door.contains(u, v) ? int(kDoor) : int(kWall); });
    mesh.begin("room.wall_west");
    tiled(
        mesh, {0, D}, {0, H}, {1, 0, 0}, [](double u, double v) { return glm::dvec3(0, v, u); },
        [](double, double) { return int(kWall); });
    mesh.begin("room.wall_east");
    tiled(
        mesh, {0, D}, {0, H}, {-1, 0, 0}, [W](double u, double v) { return glm::dvec3(W, v, u); },
        [](double, double) { return int(kWall); });
}

// A chair: local -z is its front (towards the desk), backrest at +z.
void chair(Mesh& mesh, const Frame& f, const Detail& d, const std::string& name) {
    const double seat_y = 0.43, seat_t = 0.05, leg_r = 0.012;
    for (int k = 0; k < 4; ++k) {
        mesh.begin(name + ".leg" + std::to_string(k));
        cylinder(mesh, f.child({k % 2 ? 0.2 : -0.2, 0, k / 2 ? 0.2 : -0.2}), leg_r, 0.0, seat_y, d.cylinder, kMetal,
                 false, false);
    }
    mesh.begin(name + ".seat");
    rounded_slab(mesh, f, 0.23, 0.23, 0.04, seat_y, seat_y + seat_t, 0.01, d.corner, d.edge, kChair, true);
    const double back_y = 0.55;
    for (int k = 0; k < 2; ++k) {
        mesh.begin(name + ".post" + std::to_string(k));
        cylinder(mesh, f.child({k ? 0.17 : -0.17, 0, 0.2}), leg_r, seat_y + seat_t, back_y, d.cylinder, kMetal, false,
                 false);
    }
    mesh.begin(name + ".back");
    rounded_slab(mesh, f.child({0, 0, 0.2}), 0.22, 0.02, 0.015, back_y, 0.95, 0.005, d.corner, d.edge, kChair, true);
}

// A desk: centred on x = z = 0 of its frame, the user sitting at -z.
void desk(Mesh& mesh, const Frame& f, const Detail& d, std::uint64_t seed, int id) {
    Rng rng(seed, 1, std::uint64_t(id));
    const std::string name = "desk" + std::to_string(id);
    const double y0 = kDeskY, y1 = kDeskY + kDeskT;
    mesh.begin(name + ".top");
    rounded_slab(mesh, f, kDeskW / 2, kDeskD / 2, 0.05, y0, y1, 0.006, d.corner, d.edge, kDeskTop, true);
    for (int k = 0; k < 4; ++k) {
        mesh.begin(name + ".leg" + std::to_string(k));
        cylinder(mesh, f.child({(k % 2 ? 1 : -1) * (kDeskW / 2 - 0.08), 0, (k / 2 ? 1 : -1) * (kDeskD / 2 - 0.08)}),
                 0.025, 0.0, y0, d.cylinder, kMetal, false, false);
    }
    // Pedestal with three drawers under the right end (handles on its front, at -z).
    const Frame ped = f.child({kDeskW / 2 - 0.35, 0, 0.05});
    mesh.begin(name + ".pedestal");
    box(mesh, ped, 0.2, 0.28, 0.0, 0.6, kPedestal);
    for (int k = 0; k < 3; ++k) {
        mesh.begin(name + ".handle" + std::to_string(k));
        box(mesh, ped.child({0, 0, -0.28 - 0.01}), 0.06, 0.01, 0.12 + 0.18 * k, 0.135 + 0.18 * k, kMetal, true, true,
            kPZ);
    }
    // Monitor on a round foot, keyboard, sometimes a mug.
    const double mx = rng.uniform(-0.25, 0.25);
    const Frame mon = f.child({mx, 0, 0.2}, rng.uniform(-0.15, 0.15));
    mesh.begin(name + ".monitor_foot");
    cylinder(mesh, mon, 0.1, y1, y1 + 0.015, d.cylinder * 2, kMetal, false, true);
    mesh.begin(name + ".monitor_neck");
    box(mesh, mon, 0.02, 0.012, y1 + 0.015, y1 + 0.2, kMetal, false, false);
    mesh.begin(name + ".monitor");
    rounded_slab(mesh, mon, 0.3, 0.015, 0.01, y1 + 0.2, y1 + 0.55, 0.0, d.corner, 0, kMonitor, true);
    mesh.begin(name + ".keyboard");
    box(mesh, f.child({mx + rng.uniform(-0.05, 0.05), 0, -0.18}, rng.uniform(-0.1, 0.1)), 0.22, 0.07, y1, y1 + 0.02,
        kKeyboard);
    if (rng.uniform(0, 1) < 0.5) {
        mesh.begin(name + ".mug");
        cylinder(mesh, f.child({rng.uniform(0.55, 0.7), 0, rng.uniform(0.0, 0.05)}), 0.04, y1, y1 + 0.1, d.cylinder,
                 kMug, false, true);
    }
}

void plant(Mesh& mesh, const Frame& f, const Detail& d, double y, double scale, const std::string& name) {
    const int n = d.cylinder;
    const double r0 = 0.12 * scale, r1 = 0.16 * scale, h = 0.3 * scale;
    mesh.begin(name + ".pot");
    loft(mesh, f, {{circle(r0, n), y}, {circle(r1, n), y + h}}, kPot, false, true);
    // Foliage: a surface of revolution (an egg on the soil), profile cut as finely as the pot.
    std::vector<Level> leaves;
    const int k = std::max(2, d.cylinder / 3);
    const double fr = 0.9 * r1, fh = 0.7 * scale;
    for (int i = 0; i <= k; ++i) {
        const double a = -kPi / 3 + (kPi / 3 + kPi / 2) * i / k;  // from below the equator to the apex
        const double r = i == k ? 0.0 : (fr + 0.15 * scale) * std::cos(a);
        leaves.push_back({circle(r, n), 0.0});
        leaves.back().y = y + h + (std::sin(a) - std::sin(-kPi / 3)) / (1 - std::sin(-kPi / 3)) * fh;
    }
    leaves[0].ring = circle(fr * 0.999, n);  // rests inside the pot's rim
    mesh.begin(name + ".leaves");
    loft(mesh, f, leaves, kLeaves, false, false);
}

// A bookcase against a wall: local -z is the wall, open at +z. Books are planned separately.
struct Compartment {
    Frame frame;    // the bookcase's frame
    double y;       // top of the board the books stand on
    double x0, x1;  // inner width
    double height;  // clear height
    int bookcase, level;
};
void bookcase(Mesh& mesh, const Frame& f, std::uint64_t seed, int id, std::vector<Compartment>& compartments) {
    const std::string name = "bookcase" + std::to_string(id);
    const double hx = kCaseW / 2, hz = kCaseD / 2, t = 0.02;
    for (int s = 0; s < 2; ++s) {
        mesh.begin(name + ".side" + std::to_string(s));
        box(mesh, f.child({s ? hx - t / 2 : -hx + t / 2, 0, hz}), t / 2, hz, 0.0, kCaseH, kShelf, false, true, kNZ);
    }
    // Boards between the sides: plinth, four shelves, top. Their ends touch the sides, their
    // backs the wall.
    const double levels[6] = {0.0, 0.4, 0.78, 1.16, 1.54, kCaseH - t};
    const double thick[6] = {0.08, t, t, t, t, t};
    Rng rng(seed, 2, std::uint64_t(id));
    for (int l = 0; l < 6; ++l) {
        mesh.begin(name + ".board" + std::to_string(l));
        box(mesh, f.child({0, 0, hz}), hx - t, hz, levels[l], levels[l] + thick[l], kShelf, false, true,
            kPX | kNX | kNZ);
        if (l == 5) break;
        const double y = levels[l] + thick[l];
        compartments.push_back({f.child({0, 0, hz}), y, -hx + t, hx - t, levels[l + 1] - y, id, l});
    }
    // Storage boxes on top.
    for (int b = 0; b < 2; ++b) {
        if (rng.uniform(0, 1) < 0.3) continue;
        mesh.begin(name + ".storage" + std::to_string(b));
        box(mesh, f.child({(b ? 0.2 : -0.2) + rng.uniform(-0.02, 0.02), 0, hz + 0.02}, rng.uniform(-0.1, 0.1)), 0.16,
            0.13, kCaseH, kCaseH + rng.uniform(0.18, 0.3), kStorageBox);
    }
}

struct Book {
    double x, w, h, dz;
    int colour;
};
// The books that fit a compartment, packed from the left, in order.
std::vector<Book> books_for(const Compartment& c, std::uint64_t seed) {
    Rng rng(seed, 3, std::uint64_t(c.bookcase) * 8 + std::uint64_t(c.level));
    std::vector<Book> books;
    double x = c.x0 + 0.003;
    while (true) {
        Book b;
        b.w = rng.uniform(0.015, 0.05);
        b.h = std::min(c.height - 0.03, rng.uniform(0.2, 0.32));
        b.dz = rng.uniform(0.15, 0.24);
        b.colour = rng.below(kBookColours);
        const double gap = rng.uniform(0.001, 0.004);
        if (x + b.w + 0.003 > c.x1) break;
        b.x = x + b.w / 2;
        books.push_back(b);
        x += b.w + gap;
    }
    return books;
}

struct Office {
    Mesh mesh;
    Plan plan;
    Detail detail;
    int desks = 0, chairs = 0, bookcases = 0, books = 0, book_slots = 0, windows_emitting = 0;
};

// Builds the office with `pairs` desk pairs and `books` books (-1: none, only count the slots).
Office build(int pairs, long books, const Detail& d, std::uint64_t seed) {
    Office o;
    o.detail = d;
    o.plan = plan_for(pairs);
    const Plan& p = o.plan;
    Mesh& mesh = o.mesh;
    room(mesh, p);
    // Benches: kBenchPairs pairs of facing desks side by side; chairs at both long sides.
    const double bench_len = kBenchPairs * (kDeskW + kPairGap);
    const double x_start = kCaseD + kWalkway;
    for (int i = 0; i < pairs; ++i) {
        const int bench = i / int(kBenchPairs), slot = i % int(kBenchPairs);
        const int col = bench % p.cols, row = bench / p.cols;
        const double x = x_start + col * (bench_len + kAisleX) + (slot + 0.5) * (kDeskW + kPairGap);
        const double zc = kDoorSide + row * (p.bench_z + kAisleZ) + 0.5 * p.bench_z;
        for (int side = 0; side < 2; ++side) {
            const int id = 2 * i + side;
            const double dir = side ? 1.0 : -1.0;  // side 0 faces -z (user at smaller z)
            const Frame df{{x, 0, zc + dir * (kDeskD + kPairGap) / 2}, side ? kPi : 0.0};
            desk(mesh, df, d, seed, id);
            Rng rng(seed, 4, std::uint64_t(id));
            const double front = kDeskD / 2 + kChairOffset;
            const Frame cf = df.child({rng.uniform(-0.1, 0.1), 0, -front}, kPi + rng.uniform(-0.4, 0.4));
            chair(mesh, cf, d, "chair" + std::to_string(id));
            ++o.desks, ++o.chairs;
        }
    }
    // Bookcases along both side walls, between the door walkway and the window cabinets.
    std::vector<Compartment> compartments;
    const double z0 = 1.2, z1 = p.depth - kCabinetD - 0.6;
    const int per_wall = std::max(1, int((z1 - z0) / (kCaseW + kCaseGap)));
    for (int w = 0; w < 2; ++w)
        for (int k = 0; k < per_wall; ++k) {
            const double z = z0 + (k + 0.5) * (kCaseW + kCaseGap);
            // Local -z must point at the wall: west wall (x = 0) is -x, east wall is +x.
            const Frame f = w == 0 ? Frame{{0, 0, z}, kPi / 2} : Frame{{p.width, 0, z}, -kPi / 2};
            bookcase(mesh, f, seed, o.bookcases++, compartments);
        }
    // Cabinets under the windows, with plants; big plants in the corners by the windows.
    const int cabinets = std::max(1, int((p.width - 2 * kCaseD - 1.0) / 1.2));
    const double cx0 = 0.5 * (p.width - cabinets * 1.2);
    for (int k = 0; k < cabinets; ++k) {
        const Frame f{{cx0 + (k + 0.5) * 1.2, 0, p.depth - kCabinetD / 2}, kPi};
        mesh.begin("cabinet" + std::to_string(k));
        // Open on the wall side, local -z (the frame turns it to +z); the room sees a closed front.
        box(mesh, f, 0.59, kCabinetD / 2, 0.0, kCabinetH, kShelf, false, true, kNZ);
        Rng rng(seed, 5, std::uint64_t(k));
        if (rng.uniform(0, 1) < 0.35)
            plant(mesh, f.child({rng.uniform(-0.3, 0.3), 0, 0}), d, kCabinetH, 0.5,
                  "cabinet_plant" + std::to_string(k));
    }
    plant(mesh, Frame{{kCaseD + 0.5, 0, p.depth - kCabinetD - 0.4}}, d, 0.0, 1.2, "plant_west");
    plant(mesh, Frame{{p.width - kCaseD - 0.5, 0, p.depth - kCabinetD - 0.4}}, d, 0.0, 1.2, "plant_east");

    // Books: spread over the compartments in proportion to what fits, packed from the left.
    std::vector<std::vector<Book>> fits;
    for (const auto& c : compartments) {
        fits.push_back(books_for(c, seed));
        o.book_slots += int(fits.back().size());
    }
    if (books > 0) {
        const long want = std::min<long>(books, o.book_slots);
        std::vector<long> take(compartments.size());
        long given = 0;
        for (std::size_t i = 0; i < fits.size(); ++i) given += take[i] = want * long(fits[i].size()) / o.book_slots;
        Rng rng(seed, 6, 0);
        while (given < want) {
            const std::size_t i = std::size_t(rng.below(int(fits.size())));
            if (take[i] < long(fits[i].size())) ++take[i], ++given;
        }
        for (std::size_t i = 0; i < fits.size(); ++i) {
            const Compartment& c = compartments[i];
            for (long k = 0; k < take[i]; ++k) {
                const Book& b = fits[i][std::size_t(k)];
                mesh.begin("book" + std::to_string(c.bookcase) + "_" + std::to_string(c.level) + "_" +
                           std::to_string(k));
                box(mesh, c.frame.child({b.x, 0, kCaseD / 2 - 0.01 - b.dz / 2}), b.w / 2, b.dz / 2, c.y, c.y + b.h,
                    kBook0 + b.colour);
                ++o.books;
            }
        }
    }
    return o;
}

constexpr int kTrianglesPerBook = 10;  // a box without its bottom

// Finds the desk count and book count that give `target` triangles: the most desk pairs that
// leave room for the shelves to be half full (or books to be 30% of the triangles), then books make up the rest exactly
// (to within 5 triangles).
Office build_for(long target, std::uint64_t seed) {
    const Detail d = detail_for(target);
    auto count = [&](int pairs) { return build(pairs, -1, d, seed); };
    struct Size {
        long fixed, slots;
    };
    auto size = [&](int pairs) {
        const Office o = count(pairs);
        return Size{long(o.mesh.triangles.size()), long(o.book_slots)};
    };
    const Size smallest = size(1);
    if (smallest.fixed > target)
        throw std::invalid_argument("--triangles: the smallest office has " + std::to_string(smallest.fixed) +
                                    " triangles, got " + std::to_string(target));
    // Books take at most half the shelves and at most 30% of the triangles.
    auto half_full = [&](const Size& s) {
        return s.fixed + std::min(s.slots * kTrianglesPerBook / 2, long(0.3 * double(target))) <= target;
    };
    // Bisection for the last pair count that leaves that room (it grows with the pairs).
    int lo = 1, hi = 2;
    while (half_full(size(hi))) lo = hi, hi *= 2;
    while (hi - lo > 1) {
        const int mid = (lo + hi) / 2;
        (half_full(size(mid)) ? lo : hi) = mid;
    }
    // lo may lack shelf room for the rest; lo + 1 may have too many fixed triangles.
    for (int pairs : {lo, lo + 1}) {
        const Size s = size(pairs);
        if (s.fixed <= target && target <= s.fixed + s.slots * kTrianglesPerBook)
            return build(pairs, std::lround(double(target - s.fixed) / kTrianglesPerBook), d, seed);
    }
    const Size s = size(lo);
    return build(lo, std::max(0L, std::lround(double(target - s.fixed) / kTrianglesPerBook)), d, seed);
}

void append_number(std::string& out, double v) {
    if (std::abs(v) < 5e-7) v = 0.0;
    char buf[32];
    auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::fixed, 6);
    (void)ec;
    char* e = end;
    while (e > buf && e[-1] == '0') --e;
    if (e > buf && e[-1] == '.') --e;
    out.append(buf, e);
}

// Writes path (and its .mtl beside it) through temporary files renamed into place.
void write_office(const Office& o, const std::filesystem::path& path, long requested, std::uint64_t seed) {
    namespace fs = std::filesystem;
    const fs::path mtl = fs::path(path).replace_extension(".mtl");
    auto write_atomically = [](const fs::path& target, const std::string& text) {
        const fs::path tmp = fs::path(target).concat(".tmp");
        {
            std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
            if (!out) throw std::system_error(errno, std::generic_category(), "cannot write '" + tmp.string() + "'");
            out.write(text.data(), std::streamsize(text.size()));
            out.close();
            if (!out) {
                std::error_code ignored;
                fs::remove(tmp, ignored);
                throw std::system_error(errno, std::generic_category(), "cannot write '" + tmp.string() + "'");
            }
        }
        std::error_code ec;
        fs::rename(tmp, target, ec);
        if (ec) {
            std::error_code ignored;
            fs::remove(tmp, ignored);
            throw std::system_error(ec, "cannot rename '" + tmp.string() + "' to '" + target.string() + "'");
        }
    };
    std::string m = "# bounce-office materials: Kd diffuse reflectance, Ke emitted radiosity\n";
    for (const auto& mat : materials()) {
        m += "\nnewmtl " + std::string(mat.name) + "\nKd ";
        for (int k = 0; k < 3; ++k) append_number(m, mat.kd[k]), m += k < 2 ? " " : "\n";
        m += "Ke ";
        for (int k = 0; k < 3; ++k) append_number(m, mat.ke[k]), m += k < 2 ? " " : "\n";
    }
    const Plan& p = o.plan;
    std::string s;
    s.reserve(o.mesh.triangles.size() * 60);
    char head[512];
    std::snprintf(head, sizeof head,
                  "# bounce-office --triangles %ld --seed %llu\n# room %.3f x %.3f x %.3f m (x, y up, z), "
                  "%zu triangles, %d desks, %d chairs, %d bookcases, %d books\n# detail: %d segments per cylinder, "
                  "%d per rounded corner, %d per rounded edge\nmtllib %s\n",
                  requested, static_cast<unsigned long long>(seed), p.width, kHeight, p.depth, o.mesh.triangles.size(),
                  o.desks, o.chairs, o.bookcases, o.books, o.detail.cylinder, o.detail.corner, o.detail.edge,
                  mtl.filename().string().c_str());
    s += head;
    const auto& mats = materials();
    for (std::size_t k = 0; k < o.mesh.objects.size(); ++k) {
        const Object& ob = o.mesh.objects[k];
        const bool last = k + 1 == o.mesh.objects.size();
        const std::size_t v1 = last ? o.mesh.vertices.size() : o.mesh.objects[k + 1].first_vertex;
        const std::size_t t1 = last ? o.mesh.triangles.size() : o.mesh.objects[k + 1].first_triangle;
        s += "o " + ob.name + "\n";
        for (std::size_t v = ob.first_vertex; v < v1; ++v) {
            s += "v ";
            for (int c = 0; c < 3; ++c) append_number(s, o.mesh.vertices[v][c]), s += c < 2 ? ' ' : '\n';
        }
        int current = -1;
        for (std::size_t t = ob.first_triangle; t < t1; ++t) {
            const Triangle& tr = o.mesh.triangles[t];
            if (tr.material != current) {
                current = tr.material;
                s += "usemtl ";
                s += mats[std::size_t(current)].name;
                s += '\n';
            }
            s += "f " + std::to_string(tr.a + 1) + ' ' + std::to_string(tr.b + 1) + ' ' + std::to_string(tr.c + 1) +
                 '\n';
        }
    }
    write_atomically(mtl, m);
    write_atomically(path, s);
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"bounce-office: writes an open-plan office (OBJ + MTL) of about N triangles for bounce"};
    long triangles = 10000;
    long long seed = 1;
    std::string out = "office.obj";
    bool quiet = false;
    app.add_option("--triangles,-n", triangles, "triangles to write (the result is within 5 of it)");
    app.add_option("--seed", seed, "random seed: the same seed gives the same file");
    app.add_option("-o,--output", out, "OBJ file to write; its materials go to the same name with .mtl");
    app.add_flag("--quiet,-q", quiet, "print nothing on success");
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        if (e.get_exit_code() == 0) return app.exit(e);
        std::cerr << "bounce-office: error: " << e.what() << " (see --help)\n";
        return 2;
    }
    try {
        if (triangles <= 0 || triangles > 20'000'000)
            throw std::invalid_argument("--triangles must be between 1 and 20000000, got " + std::to_string(triangles));
        if (seed < 0) throw std::invalid_argument("--seed must be 0 or more, got " + std::to_string(seed));
        const std::filesystem::path path(out);
        if (path.extension() != ".obj") throw std::invalid_argument("-o must name a .obj file, got '" + out + "'");
        if (path.filename().string().find_first_of(" \t") != std::string::npos)
            throw std::invalid_argument("-o: the file name may not contain spaces (mtllib names it), got '" + out +
                                        "'");
        const auto t0 = std::chrono::steady_clock::now();
        const Office o = build_for(triangles, std::uint64_t(seed));
        write_office(o, path, triangles, std::uint64_t(seed));
        const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        if (!quiet)
            std::printf(
                "%s: %zu triangles (asked %ld), room %.1f x %.1f x %.1f m, %d desks, %d chairs, %d bookcases, "
                "%d books, %d segments per cylinder; %.2f s\n",
                out.c_str(), o.mesh.triangles.size(), triangles, o.plan.width, o.plan.depth, kHeight, o.desks, o.chairs,
                o.bookcases, o.books, o.detail.cylinder, secs);
        return 0;
    } catch (const std::invalid_argument& e) {
        std::cerr << "bounce-office: error: " << e.what() << "\n";
        return 2;
    } catch (const std::exception& e) {
        std::cerr << "bounce-office: error: " << e.what() << "\n";
        return 1;
    }
}
