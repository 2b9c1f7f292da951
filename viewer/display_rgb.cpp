// SPDX-License-Identifier: MIT
#include "viewer/display_rgb.h"

#include <vector>

#include <vtkCellData.h>
#include <vtkDataArray.h>
#include <vtkPointData.h>
#include <vtkSmartPointer.h>
#include <vtkUnsignedCharArray.h>
#include <vtkUnstructuredGrid.h>

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

}  // namespace

void add_display_rgb(vtkUnstructuredGrid* g, double ev) {
    auto* cd = g->GetCellData();
    const auto B = rgb_values(cd->GetArray("radiosity"));
    const std::vector<Rgb> E =
        cd->GetArray("emission") ? rgb_values(cd->GetArray("emission")) : std::vector<Rgb>(B.size());
    std::vector<double> A(B.size(), 1.0);
    if (auto* a = cd->GetArray("area"))
        for (std::size_t i = 0; i < A.size(); ++i) A[i] = a->GetTuple1(vtkIdType(i));
    const ToneMap tm = ToneMap::automatic(B, E, A, ev);
    cd->AddArray(colours(tm, B));  // replaces an array of the same name
    if (auto* pb = g->GetPointData()->GetArray("radiosity"); pb && pb->GetNumberOfComponents() == 3)
        g->GetPointData()->AddArray(colours(tm, rgb_values(pb)));
}

}  // namespace bounce
