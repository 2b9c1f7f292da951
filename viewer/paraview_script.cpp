// SPDX-License-Identifier: MIT
#include "viewer/paraview_script.h"

#include <algorithm>
#include <iomanip>

#include <vtkCellData.h>
#include <vtkDataArray.h>

#include "viewer/camera.h"
#include "viewer/luminance_scale.h"
#include "viewer/pending_output.h"
#include "viewer/solution_grid.h"

namespace bounce {
namespace {

std::string py_list(const std::array<double, 3>& v) {
    std::ostringstream out;
    out << std::setprecision(17) << "[" << v[0] << ", " << v[1] << ", " << v[2] << "]";
    return out.str();
}

/// Python string literal (repr-style, enough for paths).
std::string py_str(const std::string& s) {
    std::string out = "\"";
    for (char c : s) {
        if (c == '\\' || c == '"') out += '\\';
        out += c;
    }
    return out + "\"";
}

}  // namespace

void write_paraview_script(const std::filesystem::path& script, const std::filesystem::path& vtu, const PatchMesh& mesh,
                           const SolveResult& result, const ExportInfo& info, const RenderOptions& options) {
    const auto grid = make_solution_grid(mesh, result, info);
    const CameraPose pose = choose_camera(grid, options.camera, options.fov, double(options.width) / options.height,
                                          options.camera_name, options.fov_name);
    // Luminance: the range of render's luminance colour bar (what the camera sees, the cell
    // values ParaView's luminance array holds); radiosity: over the surfaces that do not emit.
    const double max_luminance =
        luminance_scale_top(grid, pose, double(options.width) / options.height, /*points=*/false);
    double max_radiosity = 0;
    auto* e = grid->GetCellData()->GetArray("emission");
    for (std::size_t i = 0; i < mesh.size(); ++i) {
        if (e->GetComponent(vtkIdType(i), 0) > 0 || e->GetComponent(vtkIdType(i), 1) > 0 ||
            e->GetComponent(vtkIdType(i), 2) > 0)
            continue;
        max_radiosity = std::max(max_radiosity, result.radiosity[i].max());
    }
    if (!(max_radiosity > 0)) max_radiosity = 1;
    const std::string name = vtu.filename().string();
    const std::string absolute = std::filesystem::absolute(vtu).string();
    write_text_file(
        script,
        [&](std::ostream& out) {
            out << std::setprecision(17);
            out << "# Written by `bounce solve --paraview`: opens " << name
                << " in ParaView as `bounce render` shows it.\n"
                << "# GUI: View > Python Shell > Run Script.  Batch: pvbatch " << script.filename().string()
                << " [--screenshot OUT.png]\n"
                << "import os\nimport sys\n\nfrom paraview.simple import *\n\n"
                << "try:\n    here = os.path.dirname(os.path.abspath(__file__))\nexcept NameError:\n    here = \"\"\n"
                << "path = os.path.join(here, " << py_str(name) << ")\n"
                << "if not os.path.exists(path):\n    path = " << py_str(absolute) << "\n"
                << "data = XMLUnstructuredGridReader(registrationName=" << py_str(name) << ", FileName=[path])\n"
                << "view = GetActiveViewOrCreate(\"RenderView\")\n"
                << "display = Show(data, view)\n"
                << "# The picture of bounce render: the point data's tone-mapped 8-bit colours, interpolated\n"
                << "# over the cells and used as they are (Map Scalars off), unlit (radiosity is light\n"
                << "# already: Ambient 1, Diffuse 0), one-sided faces. The patch values: ColorBy CELLS.\n"
                << "ColorBy(display, (\"POINTS\", \"display_rgb\"))\n"
                << "display.MapScalars = 0\n"
                << "display.Ambient = 1.0\ndisplay.Diffuse = 0.0\n"
                << "display.BackfaceRepresentation = \"Cull Backface\"\n"
                << "HideScalarBarIfNotNeeded(GetColorTransferFunction(\"display_rgb\"), view)\n"
                << "# Switching to luminance (the Coloring menu): ranged as render --luminance, to the brightest\n"
                << "# of what this camera sees (" << luminance_unit(grid) << "); radiosity: over the surfaces that do\n"
                << "# not emit. Brighter places and the light saturate.\n"
                << "for array, top in ((\"luminance\", " << max_luminance << "), (\"radiosity\", " << max_radiosity
                << ")):\n"
                << "    lut = GetColorTransferFunction(array)\n"
                << "    lut.ApplyPreset(\"Viridis (matplotlib)\", True)\n"
                << "    lut.AutomaticRescaleRangeMode = \"Never\"\n"
                << "    lut.RescaleTransferFunction(0.0, top)\n"
                << "view.OrientationAxesVisibility = 0\n"
                << "if hasattr(view, \"UseColorPaletteForBackground\"):\n    view.UseColorPaletteForBackground = 0\n"
                << "view.Background = [0.0, 0.0, 0.0]\n"
                << "Render(view)  # paraview.simple resets the camera on a view's first render: set it after\n"
                << "view.CameraPosition = " << py_list(pose.position) << "\n"
                << "view.CameraFocalPoint = " << py_list(pose.focal_point) << "\n"
                << "view.CameraViewUp = " << py_list(pose.view_up) << "\n"
                << "view.CameraViewAngle = " << pose.view_angle << "\n"
                << "view.CameraParallelProjection = 0\n"
                << "view.ViewSize = [" << options.width << ", " << options.height << "]\n"
                << "Render(view)\n"
                << "if \"--screenshot\" in sys.argv:\n"
                << "    SaveScreenshot(sys.argv[sys.argv.index(\"--screenshot\") + 1], view, ImageResolution=["
                << options.width << ", " << options.height << "])\n";
        },
        "ParaView script");
}

}  // namespace bounce
