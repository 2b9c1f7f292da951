// SPDX-License-Identifier: MIT
#include "viewer/display_rgb.h"

#include <vector>

#include <vtkCellData.h>
#include <vtkDataArray.h>
#include <vtkIdList.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkSmartPointer.h>
#include <vtkUnsignedCharArray.h>
#include <vtkUnstructuredGrid.h>

#include "viewer/specular_cells.h"
#include "viewer/tone_map.h"

namespace bounce {
namespace {

std::vector<Rgb> rgb_values(vtkDataArray* a) {
    std::vector<Rgb> v(a ? std::size_t(a->GetNumberOfTuples()) : 0);
    for (std::size_t i = 0; i < v.size(); ++i) {
        double t[3];
        a->GetTuple(vtkIdType(i), t);
        v[i] = {t[0], t[1], t[2]};
    }
    return v;
}

vtkSmartPointer<vtkUnsignedCharArray> colours(const ToneMap& tm, const std::vector<Rgb>& values) {
    auto c = vtkSmartPointer<vtkUnsignedCharArray>::New();
    c->SetName("display_rgb");
    c->SetNumberOfComponents(3);
    c->SetComponentName(0, "R");
    c->SetComponentName(1, "G");
    c->SetComponentName(2, "B");
    c->SetNumberOfTuples(vtkIdType(values.size()));
    for (std::size_t i = 0; i < values.size(); ++i) {
        const auto px = tm(values[i]);
        c->SetTypedTuple(vtkIdType(i), px.data());
    }
    return c;
}

/// The specular cells, and their corners, in their tint (specular_tint).
void paint_specular(vtkUnstructuredGrid* g, vtkDataArray* kind, vtkUnsignedCharArray* cells,
                    vtkUnsignedCharArray* points) {
    vtkNew<vtkIdList> ids;
    for (vtkIdType c = 0; c < kind->GetNumberOfTuples(); ++c) {
        const int k = int(kind->GetTuple1(c));
        if (k == 0) continue;
        const auto tint = specular_tint(k);
        cells->SetTypedTuple(c, tint.data());
        if (!points) continue;
        g->GetCellPoints(c, ids);
        for (vtkIdType j = 0; j < ids->GetNumberOfIds(); ++j) points->SetTypedTuple(ids->GetId(j), tint.data());
    }
}

}  // namespace

void add_display_rgb(vtkUnstructuredGrid* g, double ev) {
    auto* cd = g->GetCellData();
    const auto B = rgb_values(cd->GetArray("radiosity"));
    const std::vector<Rgb> E =
        cd->GetArray("emission") ? rgb_values(cd->GetArray("emission")) : std::vector<Rgb>(B.size());
    std::vector<double> A(B.size(), 1.0);
    if (auto* a = cd->GetArray("area"))
        for (std::size_t i = 0; i < A.size(); ++i) A[i] = a->GetTuple1(vtkIdType(i));
    // Mirrors and glass hold no radiosity: they stay out of the exposure (weight 0).
    vtkDataArray* kind = cd->GetArray(kMaterialKindArray);
    if (kind)
        for (std::size_t i = 0; i < A.size(); ++i)
            if (kind->GetTuple1(vtkIdType(i)) != 0) A[i] = 0.0;
    const ToneMap tm = ToneMap::automatic(B, E, A, ev);
    auto cell_rgb = colours(tm, B);
    vtkSmartPointer<vtkUnsignedCharArray> point_rgb;
    if (auto* pb = g->GetPointData()->GetArray("radiosity"); pb && pb->GetNumberOfComponents() == 3)
        point_rgb = colours(tm, rgb_values(pb));
    if (kind) paint_specular(g, kind, cell_rgb, point_rgb);
    cd->AddArray(cell_rgb);  // replaces an array of the same name
    if (point_rgb) {
        g->GetPointData()->AddArray(point_rgb);
        // What ParaView colours by when the file is opened without the script: the smooth
        // picture's brightness, not the cells' luminance, whose range the light sets.
        g->GetPointData()->SetActiveScalars("display_rgb");
    }
}

}  // namespace bounce
