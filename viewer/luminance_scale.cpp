// SPDX-License-Identifier: MIT
#include "viewer/luminance_scale.h"

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include <vtkCell.h>
#include <vtkCellData.h>
#include <vtkDataArray.h>
#include <vtkDoubleArray.h>
#include <vtkIdList.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkUnstructuredGrid.h>

#include "viewer/solution_grid.h"

namespace bounce {
namespace {

using V3 = std::array<double, 3>;

V3 sub(const V3& a, const V3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
double dot(const V3& a, const V3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
V3 cross(const V3& a, const V3& b) {
    return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double norm(const V3& a) { return std::sqrt(dot(a, a)); }

bool emits(vtkDataArray* e, vtkIdType i) {
    return e && (e->GetComponent(i, 0) > 0 || e->GetComponent(i, 1) > 0 || e->GetComponent(i, 2) > 0);
}

/// The weighted quantile q of (value, weight) pairs.
double weighted_quantile(std::vector<std::pair<double, double>> v, double q) {
    if (v.empty()) return 0.0;
    std::sort(v.begin(), v.end());
    double total = 0;
    for (const auto& [x, w] : v) total += w;
    double run = 0;
    for (const auto& [x, w] : v) {
        run += w;
        if (run >= q * total) return x;
    }
    return v.back().first;
}

}  // namespace

bool add_point_luminance(vtkUnstructuredGrid* g) {
    vtkDataArray* b = g->GetPointData()->GetArray("radiosity");
    if (!b || b->GetNumberOfComponents() != 3) return false;
    vtkNew<vtkDoubleArray> l;
    l->SetName("luminance");
    l->SetNumberOfTuples(b->GetNumberOfTuples());
    for (vtkIdType i = 0; i < b->GetNumberOfTuples(); ++i)
        l->SetValue(i,
                    0.2126 * b->GetComponent(i, 0) + 0.7152 * b->GetComponent(i, 1) + 0.0722 * b->GetComponent(i, 2));
    g->GetPointData()->RemoveArray("luminance");
    g->GetPointData()->AddArray(l);
    return true;
}

double luminance_scale_top(vtkUnstructuredGrid* g, const CameraPose& pose, double aspect, bool points) {
    vtkDataArray* cell_l = g->GetCellData()->GetArray("luminance");
    vtkDataArray* e = g->GetCellData()->GetArray("emission");
    vtkDataArray* point_l = points ? g->GetPointData()->GetArray("luminance") : nullptr;
    if (points && !point_l && add_point_luminance(g)) point_l = g->GetPointData()->GetArray("luminance");
    const V3 eye = pose.position;
    V3 forward = sub(pose.focal_point, eye);
    const double fl = norm(forward);
    if (fl > 0)
        for (double& c : forward) c /= fl;
    // Inside the view: within the cone around the view direction that holds the picture's
    // corners (half the diagonal field of view).
    const double half_v = 0.5 * pose.view_angle * M_PI / 180.0;
    const double half_diag = std::atan(std::tan(half_v) * std::sqrt(1.0 + aspect * aspect));
    const double cos_limit = std::cos(std::min(half_diag, 0.5 * M_PI));
    std::vector<std::pair<double, double>> seen, all;
    vtkNew<vtkIdList> ids;
    for (vtkIdType c = 0; c < g->GetNumberOfCells(); ++c) {
        if (emits(e, c)) continue;
        g->GetCellPoints(c, ids);
        const vtkIdType n = ids->GetNumberOfIds();
        if (n < 3) continue;
        // Centre and area normal (Newell) of the polygon.
        V3 centre{0, 0, 0}, normal{0, 0, 0};
        std::vector<V3> p(static_cast<std::size_t>(n));
        for (vtkIdType k = 0; k < n; ++k) {
            g->GetPoint(ids->GetId(k), p[std::size_t(k)].data());
            for (int a = 0; a < 3; ++a) centre[a] += p[std::size_t(k)][a] / double(n);
        }
        for (std::size_t k = 0; k < p.size(); ++k) {
            const V3 c2 = cross(p[k], p[(k + 1) % p.size()]);
            for (int a = 0; a < 3; ++a) normal[a] += 0.5 * c2[a];
        }
        const double area = norm(normal);
        if (!(area > 0)) continue;
        std::vector<std::pair<double, double>> values;
        if (point_l)
            for (vtkIdType k = 0; k < n; ++k) values.emplace_back(point_l->GetTuple1(ids->GetId(k)), area / double(n));
        else if (cell_l)
            values.emplace_back(cell_l->GetTuple1(c), area);
        all.insert(all.end(), values.begin(), values.end());
        const V3 to_eye = sub(eye, centre);
        const double d = norm(to_eye);
        const bool faces = dot(normal, to_eye) > 0;
        const bool in_view = d > 0 && -dot(to_eye, forward) / d >= cos_limit;
        if (faces && in_view) seen.insert(seen.end(), values.begin(), values.end());
    }
    const double top = weighted_quantile(seen.empty() ? all : seen, 0.99);
    return top > 0 ? top : 1.0;
}

std::string luminance_unit(vtkUnstructuredGrid* g) {
    const std::string units = field_text(g->GetFieldData(), "units");
    return units.empty() ? "W per unit area" : "W per " + units + "^2";
}

}  // namespace bounce
