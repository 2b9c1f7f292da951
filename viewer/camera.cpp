// SPDX-License-Identifier: MIT
#include "viewer/camera.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <utility>
#include <vector>

#include <vtkCellData.h>
#include <vtkCellLocator.h>
#include <vtkDataArray.h>
#include <vtkGenericCell.h>
#include <vtkIdList.h>
#include <vtkNew.h>
#include <vtkPoints.h>
#include <vtkUnstructuredGrid.h>

#include "mesh/scene/input_error.h"
#include "viewer/solution_grid.h"

namespace bounce {
namespace {

using V3 = std::array<double, 3>;

V3 operator+(V3 a, V3 b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }
V3 operator-(V3 a, V3 b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
V3 operator*(V3 a, double s) { return {a[0] * s, a[1] * s, a[2] * s}; }
V3 axis(int k, double sign) {
    V3 a{0, 0, 0};
    a[k] = sign;
    return a;
}

constexpr double kCornellFov = 39.0;  // degrees: the published Cornell box camera
// In the Cornell view the far wall spans this share of the picture's height (tangents).
constexpr double kFarWallShare = 0.57;
constexpr double kOpenArrangementFov = 110.0;  // degrees, for scenes open on every side

/// Area vector (Newell) of a cell: normal times area.
V3 area_vector(vtkUnstructuredGrid* g, vtkIdType c, vtkIdList* ids) {
    g->GetCellPoints(c, ids);
    V3 n{0, 0, 0};
    const vtkIdType k = ids->GetNumberOfIds();
    for (vtkIdType i = 0; i < k; ++i) {
        double p[3], q[3];
        g->GetPoint(ids->GetId(i), p);
        g->GetPoint(ids->GetId((i + 1) % k), q);
        n[0] += (p[1] - q[1]) * (p[2] + q[2]);
        n[1] += (p[2] - q[2]) * (p[0] + q[0]);
        n[2] += (p[0] - q[0]) * (p[1] + q[1]);
    }
    return n * 0.5;
}

int dominant_axis(V3 v) {
    int k = 0;
    for (int i = 1; i < 3; ++i)
        if (std::abs(v[i]) > std::abs(v[k])) k = i;
    return k;
}

struct SceneUp {
    int axis = 1;       // the axis "up" lies along
    double sign = 1.0;  // and its direction
    V3 mean_normal{};   // area-weighted sum of every face's normal
};

/// Up: against the emitters' area-weighted normal (lights face down), snapped to an axis;
/// +y when there are no emitters or their normals cancel.
SceneUp scene_up(vtkUnstructuredGrid* g, double diagonal) {
    vtkNew<vtkIdList> ids;
    V3 emitting{0, 0, 0};
    SceneUp up;
    auto* e = g->GetCellData()->GetArray("emission");
    for (vtkIdType c = 0; c < g->GetNumberOfCells(); ++c) {
        const V3 a = area_vector(g, c, ids);
        up.mean_normal = up.mean_normal + a;
        if (e && (e->GetComponent(c, 0) > 0 || e->GetComponent(c, 1) > 0 || e->GetComponent(c, 2) > 0))
            emitting = emitting + a;
    }
    const double length = std::sqrt(emitting[0] * emitting[0] + emitting[1] * emitting[1] + emitting[2] * emitting[2]);
    if (length > 1e-9 * diagonal * diagonal) {
        up.axis = dominant_axis(emitting);
        up.sign = emitting[up.axis] > 0 ? -1.0 : 1.0;
    }
    return up;
}

double diagonal_of(vtkUnstructuredGrid* g) {
    double b[6];
    g->GetBounds(b);
    return std::sqrt((b[1] - b[0]) * (b[1] - b[0]) + (b[3] - b[2]) * (b[3] - b[2]) + (b[5] - b[4]) * (b[5] - b[4]));
}

double dot(V3 a, V3 b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
double length(V3 a) { return std::sqrt(dot(a, a)); }
V3 cross(V3 a, V3 b) { return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]}; }

/// How open the picture from `eye` towards `target` is: over an 8 x 8 grid of rays across the
/// frame, the mean distance to the first face the camera sees (its front towards the camera;
/// back faces are culled in the picture, so rays pass through them), relative to half of
/// `depth` and capped at 1 (what stands beyond the room's middle does not block the view). A camera inside an object
/// (most rays meet a back face first) scores 0: the picture would show the room through the object's inside.
double view_openness(vtkUnstructuredGrid* g, vtkCellLocator* locator, V3 eye, V3 target, V3 up, double view_angle,
                     double aspect, double depth) {
    const V3 forward = (target - eye) * (1.0 / std::max(length(target - eye), 1e-300));
    V3 right = cross(forward, up);
    right = right * (1.0 / std::max(length(right), 1e-300));
    const V3 true_up = cross(right, forward);
    const double tv = std::tan(view_angle * M_PI / 360.0), th = tv * aspect;
    vtkNew<vtkIdList> ids;
    constexpr int kRays = 8;
    double sum = 0;
    int inside = 0;
    for (int i = 0; i < kRays; ++i)
        for (int j = 0; j < kRays; ++j) {
            const double x = th * (-1 + 2 * (i + 0.5) / kRays), y = tv * (-1 + 2 * (j + 0.5) / kRays);
            V3 dir = forward + right * x + true_up * y;
            dir = dir * (1.0 / length(dir));
            V3 from = eye;
            double travelled = 0, seen = 2 * depth;
            bool first = true;
            for (int hop = 0; hop < 16; ++hop) {  // past the back faces to the first front one
                const V3 to = from + dir * (2.0 * depth);
                double tt, xx[3], pc[3];
                int sub;
                vtkIdType cell = -1;
                if (!locator->IntersectWithLine(from.data(), to.data(), 1e-9, tt, xx, pc, sub, cell)) break;
                const double d = tt * 2.0 * depth;
                const bool front = dot(area_vector(g, cell, ids), dir) < 0;
                if (front) {
                    seen = travelled + d;
                    break;
                }
                if (first) ++inside;
                first = false;
                travelled += d + 1e-6 * depth;
                from = from + dir * (d + 1e-6 * depth);
            }
            sum += std::min(1.0, seen / (0.5 * depth));
        }
    if (inside > kRays * kRays / 4) return 0.0;
    return sum / (kRays * kRays);
}

/// The share of rays from inside the box lo-hi out through its side k (outward sign) that
/// meet nothing: an 8 x 8 grid over the side, away from its edges; `up` the vertical axis.
double side_openness(vtkCellLocator* locator, const V3& lo, const V3& hi, double diagonal, int up, int k, double sign) {
    const V3 size = hi - lo, centre = (lo + hi) * 0.5;
    const int w = 3 - k - up;  // the side's horizontal axis
    int free_rays = 0;
    constexpr int kSamples = 8;
    for (int i = 0; i < kSamples; ++i)
        for (int j = 0; j < kSamples; ++j) {
            V3 p = centre;
            p[w] = lo[w] + size[w] * (0.05 + 0.9 * (i + 0.5) / kSamples);
            p[up] = lo[up] + size[up] * (0.05 + 0.9 * (j + 0.5) / kSamples);
            V3 q = p;
            q[k] = sign > 0 ? hi[k] + 0.01 * diagonal : lo[k] - 0.01 * diagonal;
            double tt, x[3], pc[3];
            int sub;
            if (!locator->IntersectWithLine(p.data(), q.data(), 1e-9, tt, x, pc, sub)) ++free_rays;
        }
    return double(free_rays) / (kSamples * kSamples);
}

CameraPose auto_camera(vtkUnstructuredGrid* g, double fov, double aspect) {
    double b[6];
    g->GetBounds(b);
    const V3 lo{b[0], b[2], b[4]}, hi{b[1], b[3], b[5]};
    const V3 size = hi - lo, centre = (lo + hi) * 0.5;
    const double diagonal = std::sqrt(size[0] * size[0] + size[1] * size[1] + size[2] * size[2]);
    CameraPose pose;
    pose.view_angle = fov > 0 ? fov : kCornellFov;
    const double t = std::tan(pose.view_angle * M_PI / 360.0);

    const SceneUp su = scene_up(g, diagonal);
    const int up = su.axis;
    const double up_sign = su.sign;
    const V3 all = su.mean_normal;

    // A flat scene (one extent near zero): face-on from the side its faces look to.
    const int thin = int(std::min_element(size.begin(), size.end()) - size.begin());
    if (size[thin] < 1e-3 * diagonal) {
        const double front = all[thin] >= 0 ? 1.0 : -1.0;
        const int u = thin == 1 ? 2 : 1;
        const double half = 0.5 * std::max({size[0], size[1], size[2]});
        pose.focal_point = centre;
        pose.position = centre + axis(thin, front) * (half / t * 1.1);
        pose.view_up = axis(u, 1.0);
        return pose;
    }

    vtkNew<vtkCellLocator> locator;
    locator->SetDataSet(g);
    locator->BuildLocator();
    struct Side {
        int k;        // axis of the side's normal
        double sign;  // outward direction along it
        double open;  // share of rays out through it that meet nothing
    };
    Side best{-1, 0, -1};
    int open_sides = 0;
    const int order[3] = {2, 1, 0};  // ties: -z, -y, -x, then +
    for (double sign : {-1.0, 1.0})
        for (int k : order) {
            if (k == up) continue;
            const double open = side_openness(locator, lo, hi, diagonal, up, k, sign);
            if (open >= 0.5) ++open_sides;
            const bool longer = size[k] > size[best.k < 0 ? k : best.k] * 1.001;
            if (best.k < 0 || open > best.open + 0.05 || (std::abs(open - best.open) <= 0.05 && longer))
                best = {k, sign, open};
        }
    const int k = best.k, w = 3 - k - up;
    const V3 out = axis(k, best.sign);  // from the room towards the camera
    V3 side_centre = centre;
    side_centre[k] = best.sign > 0 ? hi[k] : lo[k];
    // Half extents the picture must hold: vertical, and horizontal over the aspect ratio.
    const double half = std::max(0.5 * size[up], 0.5 * size[w] / std::max(aspect, 1e-3));
    pose.view_up = axis(up, up_sign);
    if (open_sides == 4) {
        // No walls at all (objects in the open, such as two facing plates): from the Cornell
        // distance most of a level view is the gap between them, so stand at the edge of the
        // arrangement and look across it with a wide view.
        pose.focal_point = side_centre - out * size[k];
        pose.position = side_centre;
        if (fov <= 0) pose.view_angle = kOpenArrangementFov;
    } else if (best.open >= 0.5) {
        pose.focal_point = side_centre;
        pose.position = side_centre + out * (half / t);
    } else {
        // Inside, 2% of the depth in front of a wall, looking at the far wall. The most open
        // wall's centre first; but an object standing before it (a cube filling the frame) or
        // around it (the camera inside it) blocks that view, so the centres and off-centre
        // places of all four walls are tried with rays: the most open wall's centre stays
        // unless another place is more than 10% more open, then the most open place wins.
        struct Candidate {
            CameraPose pose;
            double openness = 0;
        };
        std::vector<Candidate> candidates;
        std::vector<std::pair<int, double>> walls = {{k, best.sign}};
        for (double sign : {-1.0, 1.0})
            for (int a : order)
                if (a != up && !(a == k && sign == best.sign)) walls.emplace_back(a, sign);
        for (const auto& [wk, wsign] : walls) {
            const int ww = 3 - wk - up;
            const V3 wout = axis(wk, wsign);
            V3 wall_centre = centre;
            wall_centre[wk] = wsign > 0 ? hi[wk] : lo[wk];
            const double depth = size[wk];
            const double wall_half = std::max(0.5 * size[up], 0.5 * size[ww] / std::max(aspect, 1e-3));
            CameraPose p = pose;
            if (fov <= 0) {
                const double tan_half =
                    std::min(wall_half / (0.98 * depth) / kFarWallShare, std::tan(50.0 * M_PI / 180));
                p.view_angle = 2.0 * std::atan(tan_half) * 180.0 / M_PI;
            }
            const V3 far = wall_centre - wout * depth;
            for (const double across : {0.0, -0.3, 0.3})
                for (const double height : {0.0, 0.25}) {
                    const V3 eye = wall_centre - wout * (0.02 * depth) + axis(ww, across * size[ww]) +
                                   axis(up, up_sign * height * size[up]);
                    p.position = eye;
                    p.focal_point = far;
                    candidates.push_back(
                        {p, view_openness(g, locator, eye, far, pose.view_up, p.view_angle, aspect, depth)});
                }
        }
        const Candidate* chosen = &candidates.front();
        for (const auto& c : candidates)
            if (c.openness > chosen->openness) chosen = &c;
        pose = candidates.front().openness >= 0.9 * chosen->openness ? candidates.front().pose : chosen->pose;
    }
    return pose;
}

}  // namespace

CameraPose choose_camera(vtkUnstructuredGrid* g, const std::string& spec, double fov, double aspect,
                         const std::string& camera_name, const std::string& fov_name) {
    if (!(fov == 0 || (fov >= 1 && fov <= 170)))
        throw InputError(fov_name + ": field of view, got " + std::to_string(fov) + " (expected 1 to 170 degrees)");
    std::string s = spec;
    if (s == "default") s = field_text(g->GetFieldData(), "scene") == "cornell" ? "cornell" : "auto";
    CameraPose pose;
    if (s == "cornell") {
        // The classic front view of the published Cornell box (camera at z = -800 looking in).
        pose.position = {278, 273, -800};
        pose.focal_point = {278, 273, 0};
        pose.view_angle = fov > 0 ? fov : kCornellFov;
        return pose;
    }
    if (s == "auto") return auto_camera(g, fov, aspect);
    double v[6];
    char sep1, sep2, colon, sep3, sep4;
    std::istringstream in(s);
    if (!(in >> v[0] >> sep1 >> v[1] >> sep2 >> v[2] >> colon >> v[3] >> sep3 >> v[4] >> sep4 >> v[5]) || sep1 != ',' ||
        sep2 != ',' || colon != ':' || sep3 != ',' || sep4 != ',' || !in.eof())
        throw InputError(camera_name + ": camera, got '" + spec + "' (expected cornell, auto or x,y,z:tx,ty,tz)");
    pose.position = {v[0], v[1], v[2]};
    pose.focal_point = {v[3], v[4], v[5]};
    // The scene's up, unless the view runs along it; then the next axis.
    const SceneUp su = scene_up(g, diagonal_of(g));
    const V3 d = pose.focal_point - pose.position;
    const double dl = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    pose.view_up = axis(su.axis, su.sign);
    if (dl > 0 && std::abs(d[su.axis]) > 0.99 * dl) pose.view_up = axis((su.axis + 1) % 3, 1.0);
    pose.view_angle = fov > 0 ? fov : 30.0;
    return pose;
}

}  // namespace bounce
