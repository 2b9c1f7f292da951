// SPDX-License-Identifier: MIT
#include "viewer/vtu_writer.h"

#include <unistd.h>
#include <cstdint>
#include <sstream>
#include <stdexcept>
#include <system_error>

#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkCharArray.h>
#include <vtkDataArray.h>
#include <vtkDoubleArray.h>
#include <vtkFieldData.h>
#include <vtkIntArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkStringArray.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLUnstructuredGridWriter.h>

#include <vtkXMLUnstructuredGridReader.h>
#include "mesh/scene/input_error.h"
#include "viewer/display_rgb.h"
#include "viewer/pending_output.h"
#include "viewer/solution_grid.h"
#include "viewer/specular_cells.h"
#include "viewer/version.h"

namespace bounce {
namespace {

vtkNew<vtkDoubleArray> rgb_array(const char* name, std::size_t n) {
    vtkNew<vtkDoubleArray> a;
    a->SetName(name);
    a->SetNumberOfComponents(3);
    a->SetComponentName(0, "R");
    a->SetComponentName(1, "G");
    a->SetComponentName(2, "B");
    a->SetNumberOfTuples(vtkIdType(n));
    return a;
}

void set_rgb(vtkDoubleArray* a, std::size_t i, const Rgb& c) {
    const double v[3] = {c.r, c.g, c.b};
    a->SetTypedTuple(vtkIdType(i), v);
}

void add_field(vtkFieldData* fd, const char* name, const std::string& value, bool as_chars) {
    // ParaView shows a string array as text and a char array as a range of character codes;
    // meshio (5.x) refuses the whole file when it meets the XML type "String", in any format.
    // No encoding satisfies both, so text is a string array unless the caller asks for chars.
    if (!as_chars) {
        vtkNew<vtkStringArray> a;
        a->SetName(name);
        a->InsertNextValue(value);
        fd->AddArray(a);
        return;
    }
    if (value.empty()) return;  // zero-length arrays trip meshio's reader
    vtkNew<vtkCharArray> a;
    a->SetName(name);
    for (char c : value) a->InsertNextValue(c);
    fd->AddArray(a);
}

void add_field(vtkFieldData* fd, const char* name, double value) {
    vtkNew<vtkDoubleArray> a;
    a->SetName(name);
    a->InsertNextValue(value);
    fd->AddArray(a);
}

void add_field(vtkFieldData* fd, const char* name, const Rgb& value) {
    vtkNew<vtkDoubleArray> a;
    a->SetName(name);
    a->SetNumberOfComponents(3);
    const double v[3] = {value.r, value.g, value.b};
    a->InsertNextTypedTuple(v);
    fd->AddArray(a);
}

}  // namespace

vtkSmartPointer<vtkUnstructuredGrid> make_solution_grid(const PatchMesh& mesh, const SolveResult& result,
                                                        const ExportInfo& info) {
    const auto& patches = mesh.patches();
    const std::size_t n = patches.size();
    if (result.radiosity.size() != n) throw std::runtime_error("write_vtu: solution and mesh differ in size");
    const auto& om = mesh.mesh();

    auto grid = vtkSmartPointer<vtkUnstructuredGrid>::New();
    vtkNew<vtkPoints> points;
    points->SetDataTypeToDouble();
    points->SetNumberOfPoints(vtkIdType(om.n_vertices()));
    for (auto v : om.vertices()) {
        const auto p = om.point(v);
        points->SetPoint(v.idx(), p[0], p[1], p[2]);
    }
    grid->SetPoints(points);
    grid->Allocate(vtkIdType(n));

    auto radiosity = rgb_array("radiosity", n);
    auto emission = rgb_array("emission", n);
    auto reflectance = rgb_array("reflectance", n);
    auto irradiance = rgb_array("irradiance", n);
    vtkNew<vtkDoubleArray> luminance, area;
    luminance->SetName("luminance");
    luminance->SetNumberOfTuples(vtkIdType(n));
    area->SetName("area");
    area->SetNumberOfTuples(vtkIdType(n));
    vtkNew<vtkIntArray> surface;
    surface->SetName("surface");
    surface->SetNumberOfTuples(vtkIdType(n));

    for (std::size_t i = 0; i < n; ++i) {
        const auto ids = mesh.patch_vertex_indices(i);
        std::vector<vtkIdType> cell(ids.begin(), ids.end());
        // Conforming element meshes carry extra points on their edges: general polygons.
        const int type = ids.size() == 3 ? VTK_TRIANGLE : (ids.size() == 4 ? VTK_QUAD : VTK_POLYGON);
        grid->InsertNextCell(type, vtkIdType(cell.size()), cell.data());
        const Patch& p = patches[i];
        set_rgb(radiosity, i, result.radiosity[i]);
        set_rgb(emission, i, p.emission);
        set_rgb(reflectance, i, p.reflectance);
        set_rgb(irradiance, i, result.irradiance.size() == n ? result.irradiance[i] : Rgb());
        luminance->SetValue(vtkIdType(i), result.radiosity[i].luminance());
        area->SetValue(vtkIdType(i), p.area);
        surface->SetValue(vtkIdType(i), p.surface);
    }
    auto cd = grid->GetCellData();
    cd->AddArray(radiosity);
    cd->AddArray(emission);
    cd->AddArray(reflectance);
    cd->AddArray(irradiance);
    cd->AddArray(luminance);
    cd->AddArray(area);
    cd->AddArray(surface);
    cd->SetActiveScalars("luminance");

    if (result.gathered_centres.size() == n) {
        auto g = rgb_array("radiosity_gathered", n);
        for (std::size_t i = 0; i < n; ++i) set_rgb(g, i, result.gathered_centres[i]);
        cd->AddArray(g);
    }
    if (result.display.size() == n) {
        auto display = rgb_array("radiosity_ambient", n);
        for (std::size_t i = 0; i < n; ++i) set_rgb(display, i, result.display[i]);
        cd->AddArray(display);
    }

    // Point data: gathered at the vertices when the solve did so (exact kernel and visibility),
    // else the area-weighted mean of the patches around each vertex.
    const std::vector<Rgb> at_vertex = result.point_radiosity.size() == om.n_vertices()
                                           ? result.point_radiosity
                                           : area_weighted_vertex_values(mesh, result.radiosity);
    auto point_radiosity = rgb_array("radiosity", om.n_vertices());
    for (std::size_t v = 0; v < om.n_vertices(); ++v) set_rgb(point_radiosity, v, at_vertex[v]);
    grid->GetPointData()->AddArray(point_radiosity);
    add_specular_cells(grid, mesh.specular_faces());
    add_display_rgb(grid, 0.0);

    auto fd = grid->GetFieldData();
    add_field(fd, "scene", info.scene, info.text_as_chars);
    add_field(fd, "solver", result.solver, info.text_as_chars);
    add_field(fd, "form_factors", result.form_factors, info.text_as_chars);
    add_field(fd, "settings", info.settings, info.text_as_chars);
    add_field(fd, "version", std::string(kBounceVersion), info.text_as_chars);
    if (!info.units.empty()) add_field(fd, "units", info.units, info.text_as_chars);
    add_field(fd, "steps", double(result.steps));
    add_field(fd, "unshot_fraction", result.unshot_fraction);
    add_field(fd, "converged", result.converged ? 1.0 : 0.0);
    add_field(fd, "status", to_string(result.status), info.text_as_chars);
    add_field(fd, "residual", result.residual);
    add_field(fd, "seconds", result.seconds);
    add_field(fd, "emitted_power", result.emitted_power);
    add_field(fd, "absorbed_power", result.absorbed_power);
    add_field(fd, "escaped_power", result.escaped_power);
    add_field(fd, "unshot_power", result.unshot_power);
    return grid;
}

void write_vtu(const std::filesystem::path& path, const PatchMesh& mesh, const SolveResult& result,
               const ExportInfo& info, bool ascii) {
    write_grid(path, make_solution_grid(mesh, result, info), ascii);
}

void write_grid(const std::filesystem::path& path, vtkUnstructuredGrid* grid, bool ascii) {
    // Temporary name in the same directory, so the final rename is atomic.
    std::filesystem::path tmp = path;
    tmp += ".tmp-" + std::to_string(::getpid());
    const PendingOutput pending(tmp.c_str());
    vtkNew<vtkXMLUnstructuredGridWriter> writer;
    writer->SetFileName(tmp.string().c_str());
    writer->SetInputData(grid);
    if (ascii) {
        writer->SetDataModeToAscii();
    } else {
        writer->SetDataModeToAppended();
        writer->SetCompressorTypeToZLib();
    }
    const int ok = writer->Write();
    commit_output(tmp, path, ok && writer->GetErrorCode() == 0, ".vtu file");
}

std::string field_text(vtkFieldData* fd, const char* name) {
    if (auto* s = vtkStringArray::SafeDownCast(fd->GetAbstractArray(name)))
        return s->GetNumberOfValues() > 0 ? s->GetValue(0) : "";
    std::string out;
    if (auto* a = fd->GetArray(name))
        for (vtkIdType i = 0; i < a->GetNumberOfTuples(); ++i) out += char(a->GetTuple1(i));
    return out;
}

vtkSmartPointer<vtkUnstructuredGrid> read_solution_grid(const std::filesystem::path& path) {
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) throw InputError(path.string() + ": file not found");
    if (std::filesystem::is_directory(path, ec)) throw InputError(path.string() + ": is a directory, expected a .vtu");
    auto reader = vtkSmartPointer<vtkXMLUnstructuredGridReader>::New();
    if (!reader->CanReadFile(path.string().c_str()))
        throw InputError(path.string() + ": not a readable VTK unstructured grid (.vtu)");
    // VTK reports parse errors through its output window; keep them off the terminal and
    // decide from the result.
    reader->GlobalWarningDisplayOff();
    reader->SetFileName(path.string().c_str());
    reader->Update();
    vtkUnstructuredGrid* g = reader->GetOutput();
    vtkDataArray* b = g ? g->GetCellData()->GetArray("radiosity") : nullptr;
    if (reader->GetErrorCode() != 0 || !g || g->GetNumberOfCells() == 0 || !b || b->GetNumberOfComponents() != 3 ||
        b->GetNumberOfTuples() != g->GetNumberOfCells())
        throw InputError(path.string() + ": corrupt .vtu or no 3-component cell array 'radiosity'");
    vtkSmartPointer<vtkUnstructuredGrid> out = g;
    return out;
}

std::string unfinished_caption(vtkUnstructuredGrid* g) {
    vtkFieldData* fd = g->GetFieldData();
    vtkDataArray* converged = fd ? fd->GetArray("converged") : nullptr;
    if (!converged || converged->GetNumberOfTuples() < 1 || converged->GetTuple1(0) != 0) return "";
    std::ostringstream s;
    s << "NOT CONVERGED";
    if (const std::string status = field_text(fd, "status"); !status.empty()) s << " (" << status << ")";
    const char* sep = ": ";
    if (vtkDataArray* steps = fd->GetArray("steps"); steps && steps->GetNumberOfTuples() > 0) {
        s << " after " << std::int64_t(steps->GetTuple1(0)) << " steps";
        sep = ", ";
    }
    vtkDataArray* unshot = fd->GetArray("unshot_fraction");
    vtkDataArray* residual = fd->GetArray("residual");
    if (unshot && unshot->GetNumberOfTuples() > 0 && unshot->GetTuple1(0) > 0)
        s << sep << "unshot fraction " << unshot->GetTuple1(0);
    else if (residual && residual->GetNumberOfTuples() > 0 && residual->GetTuple1(0) >= 0)
        s << sep << "residual " << residual->GetTuple1(0);
    return s.str();
}

}  // namespace bounce
