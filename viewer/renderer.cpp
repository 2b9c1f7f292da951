// SPDX-License-Identifier: MIT
#include "viewer/renderer.h"

#include <algorithm>
#include <cctype>
#include <cmath>

#include <vtkActor.h>
#include <vtkCallbackCommand.h>
#include <vtkCamera.h>
#include <vtkCellData.h>
#include <vtkDataSetMapper.h>
#include <vtkDoubleArray.h>
#include <vtkFieldData.h>
#include <vtkInteractorStyleTrackballCamera.h>
#include <vtkLookupTable.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkProperty.h>
#include <vtkRenderWindow.h>
#include <vtkRenderWindowInteractor.h>
#include <vtkRenderer.h>
#include <vtkScalarBarActor.h>
#include <vtkStringArray.h>
#include <vtkTextActor.h>
#include <vtkTextProperty.h>
#include <vtkUnsignedCharArray.h>
#include <vtkWindowToImageFilter.h>

#include "mesh/scene/input_error.h"
#include "viewer/camera.h"
#include "viewer/display_rgb.h"
#include "viewer/luminance_scale.h"
#include "viewer/pending_output.h"
#include "viewer/picture_writer.h"
#include "viewer/solution_grid.h"
#include "viewer/specular_actors.h"
#include "viewer/tone_map.h"
#include "viewer/virtual_display.h"

namespace bounce {
namespace {

void set_camera(vtkRenderer* ren, const CameraPose& pose) {
    vtkCamera* cam = ren->GetActiveCamera();
    cam->SetPosition(pose.position.data());
    cam->SetFocalPoint(pose.focal_point.data());
    cam->SetViewUp(pose.view_up.data());
    cam->SetViewAngle(pose.view_angle);
    cam->OrthogonalizeViewUp();
    ren->ResetCameraClippingRange();
}

struct Scene3d {
    SpecularSplit split;  // the patches, drawn by their radiosity; the mirrors and glass apart
    vtkNew<vtkRenderer> renderer;
    vtkNew<vtkRenderWindow> window;
    vtkNew<vtkDataSetMapper> mapper;
    vtkNew<vtkActor> actor;
    vtkNew<vtkScalarBarActor> bar;
    vtkNew<vtkRenderer> legend;  // beside the scene: the colour bar's own strip of the window
    vtkNew<vtkLookupTable> lut;
    vtkNew<vtkTextActor> caption;  // an unfinished solution says so in the corner
    bool luminance = false;
    bool smooth = true;
    bool point_luminance = false;  // the point array `luminance` added: smooth luminance colours
    std::string bar_title;

    Scene3d(vtkUnstructuredGrid* whole, const RenderOptions& o) : split(split_specular(whole)), smooth(o.smooth) {
        vtkUnstructuredGrid* g = split.diffuse;
        if (o.width < 16 || o.height < 16 || o.width > 8192 || o.height > 8192)
            throw InputError(o.size_name + ": out of range, got " + std::to_string(o.width) + "x" +
                             std::to_string(o.height) + " (expected 16x16 to 8192x8192)");
        add_display_rgb(g, o.exposure);
        mapper->SetInputData(g);
        actor->SetMapper(mapper);
        // Radiosity is view-independent light: no shading on top of it.
        actor->GetProperty()->LightingOff();
        // Faces are one-sided: a back face reflects nothing, and culling lets a camera outside
        // a closed room see in through the wall between (the wall's front faces the room).
        actor->GetProperty()->BackfaceCullingOn();
        actor->GetProperty()->SetEdgeColor(0.1, 0.1, 0.1);
        actor->GetProperty()->SetEdgeVisibility(o.edges);
        // Colour range from what the picture shows (luminance_scale_top): the brightest visible
        // places, the lights and faces the camera cannot see saturate instead of flattening the
        // walls into one colour. Smooth pictures colour by the point data's luminance.
        const CameraPose pose =
            choose_camera(g, o.camera, o.fov, double(o.width) / o.height, o.camera_name, o.fov_name);
        point_luminance = smooth && add_point_luminance(g);
        double range[2] = {0, luminance_scale_top(g, pose, double(o.width) / o.height, point_luminance)};
        // Viridis (perceptually uniform, readable in grey and by colour-blind eyes), from five of
        // matplotlib's control colours, linearly between them.
        static constexpr double kViridis[5][3] = {{0.267, 0.005, 0.329},
                                                  {0.229, 0.322, 0.546},
                                                  {0.128, 0.567, 0.551},
                                                  {0.369, 0.789, 0.383},
                                                  {0.993, 0.906, 0.144}};
        lut->SetNumberOfTableValues(256);
        for (int k = 0; k < 256; ++k) {
            const double t = 4.0 * k / 255.0;
            const int i = std::min(3, int(t));
            const double f = t - i;
            lut->SetTableValue(k, (1 - f) * kViridis[i][0] + f * kViridis[i + 1][0],
                               (1 - f) * kViridis[i][1] + f * kViridis[i + 1][1],
                               (1 - f) * kViridis[i][2] + f * kViridis[i + 1][2], 1.0);
        }
        lut->SetTableRange(range);
        bar->SetLookupTable(lut);
        const std::string unit = luminance_unit(g);
        const auto space = unit.rfind(' ');  // "W per\nmm^2", "W per unit\narea": the strip is narrow
        bar_title = "luminance\n(" + unit.substr(0, space) + "\n" + unit.substr(space + 1) + ")";
        bar->SetTitle(bar_title.c_str());
        bar->SetNumberOfLabels(5);
        bar->SetVerticalTitleSeparation(8);  // the three-line title clear of the top label
        bar->GetTitleTextProperty()->SetFontSize(14);
        // Beside the picture, not on it: the scene keeps the left 84% of the window, the bar
        // fills a strip of its own to the right.
        bar->SetPosition(0.1, 0.08);
        bar->SetWidth(0.8);
        bar->SetHeight(0.84);
        renderer->AddActor(actor);
        for (const auto& a : split.specular) renderer->AddActor(a);
        if (const std::string text = unfinished_caption(g); !text.empty()) {
            caption->SetInput(text.c_str());
            caption->GetTextProperty()->SetFontSize(std::max(12, o.height / 40));
            caption->GetTextProperty()->SetColor(1.0, 0.85, 0.2);
            caption->GetTextProperty()->SetBackgroundColor(0.0, 0.0, 0.0);
            caption->GetTextProperty()->SetBackgroundOpacity(0.6);
            caption->SetDisplayPosition(std::max(4, o.width / 100), std::max(4, o.height / 100));
            renderer->AddActor2D(caption);
        }
        legend->AddActor2D(bar);
        legend->SetBackground(0.0, 0.0, 0.0);
        legend->SetViewport(0.84, 0.0, 1.0, 1.0);
        renderer->SetBackground(0.0, 0.0, 0.0);
        window->AddRenderer(renderer);
        window->AddRenderer(legend);
        window->SetSize(o.width, o.height);
        set_colouring(o.luminance, o.smooth);
        set_camera(renderer, pose);
    }
    void set_colouring(bool lum, bool smooth) {
        luminance = lum;
        if (lum) {
            point_luminance ? mapper->SetScalarModeToUsePointFieldData() : mapper->SetScalarModeToUseCellFieldData();
            mapper->SelectColorArray("luminance");
            mapper->SetColorModeToMapScalars();
            mapper->SetLookupTable(lut);
            mapper->UseLookupTableScalarRangeOn();
        } else {
            smooth ? mapper->SetScalarModeToUsePointFieldData() : mapper->SetScalarModeToUseCellFieldData();
            mapper->SelectColorArray("display_rgb");
            mapper->SetColorModeToDirectScalars();
        }
        mapper->ScalarVisibilityOn();
        bar->SetVisibility(lum);
        renderer->SetViewport(0.0, 0.0, lum ? 0.84 : 1.0, 1.0);
        legend->SetDraw(lum);
    }
};

/// Smooth by default: a .vtu without point data (not bounce's) is drawn flat, unless --smooth
/// was asked for by name.
RenderOptions without_point_data_flat(vtkUnstructuredGrid* g, RenderOptions o, const std::filesystem::path& what) {
    if (!o.smooth || g->GetPointData()->GetArray("radiosity")) return o;
    if (o.smooth_required) throw InputError(what.string() + ": --smooth needs point data 'radiosity' in the input");
    o.smooth = false;
    return o;
}

void render_grid(vtkUnstructuredGrid* g, const std::filesystem::path& png, const RenderOptions& o) {
    check_picture_path(png);
    VirtualDisplay display;
    Scene3d s(g, without_point_data_flat(g, o, png));
    s.window->SetOffScreenRendering(1);
    s.window->Render();
    vtkNew<vtkWindowToImageFilter> grab;
    grab->SetInput(s.window);
    grab->ReadFrontBufferOff();
    grab->Update();
    write_picture(grab->GetOutput(), png);
}

void keypress(vtkObject* caller, unsigned long, void* client, void*) {
    auto* iren = static_cast<vtkRenderWindowInteractor*>(caller);
    auto* s = static_cast<Scene3d*>(client);
    const std::string key = iren->GetKeySym() ? iren->GetKeySym() : "";
    if (key == "e") s->actor->GetProperty()->SetEdgeVisibility(!s->actor->GetProperty()->GetEdgeVisibility());
    if (key == "l") s->set_colouring(!s->luminance, s->smooth);
    iren->Render();
}

void timer_exit(vtkObject* caller, unsigned long, void*, void*) {
    static_cast<vtkRenderWindowInteractor*>(caller)->TerminateApp();
}

void view_grid(vtkUnstructuredGrid* g, const RenderOptions& o, double exit_after) {
    VirtualDisplay display;
    Scene3d s(g, without_point_data_flat(g, o, "view"));
    s.window->SetWindowName("bounce: e edges, l luminance, mouse to rotate and zoom");
    vtkNew<vtkRenderWindowInteractor> iren;
    vtkNew<vtkInteractorStyleTrackballCamera> style;
    iren->SetInteractorStyle(style);
    iren->SetRenderWindow(s.window);
    vtkNew<vtkCallbackCommand> keys;
    keys->SetCallback(keypress);
    keys->SetClientData(&s);
    iren->AddObserver(vtkCommand::KeyPressEvent, keys);
    vtkNew<vtkCallbackCommand> quit;
    quit->SetCallback(timer_exit);
    iren->Initialize();
    if (exit_after > 0) {
        iren->AddObserver(vtkCommand::TimerEvent, quit);
        iren->CreateOneShotTimer(unsigned(exit_after * 1000));
    }
    s.window->Render();
    iren->Start();
}

}  // namespace

void check_picture_path(const std::filesystem::path& picture) {
    const std::string ext = picture_extension(picture);
    if (ext != ".png" && ext != ".jpg" && ext != ".jpeg")
        throw InputError(picture.string() + ": picture format, got '" + picture.extension().string() +
                         "' (expected .png, .jpg or .jpeg)");
}

void render_vtu(const std::filesystem::path& vtu, const std::filesystem::path& png, const RenderOptions& options,
                const UnfinishedNote& note) {
    const auto grid = read_solution_grid(vtu);
    if (const std::string text = unfinished_caption(grid); !text.empty() && note) note(text);
    render_grid(grid, png, options);
}

void render_solution(const PatchMesh& mesh, const SolveResult& result, const ExportInfo& info,
                     const std::filesystem::path& png, const RenderOptions& options) {
    render_grid(make_solution_grid(mesh, result, info), png, options);
}

void view_vtu(const std::filesystem::path& vtu, const RenderOptions& options, double exit_after,
              const UnfinishedNote& note) {
    const auto grid = read_solution_grid(vtu);
    if (const std::string text = unfinished_caption(grid); !text.empty() && note) note(text);
    view_grid(grid, options, exit_after);
}

void view_solution(const PatchMesh& mesh, const SolveResult& result, const ExportInfo& info,
                   const RenderOptions& options, double exit_after) {
    view_grid(make_solution_grid(mesh, result, info), options, exit_after);
}

}  // namespace bounce
