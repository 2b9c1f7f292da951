// SPDX-License-Identifier: MIT
#include "viewer/renderer.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <sstream>
#include <unistd.h>

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
#include <vtkImageWriter.h>
#include <vtkJPEGWriter.h>
#include <vtkPNGWriter.h>
#include <vtkPointData.h>
#include <vtkProperty.h>
#include <vtkRenderWindow.h>
#include <vtkRenderWindowInteractor.h>
#include <vtkRenderer.h>
#include <vtkScalarBarActor.h>
#include <vtkStringArray.h>
#include <vtkTextProperty.h>
#include <vtkUnsignedCharArray.h>
#include <vtkWindowToImageFilter.h>

#include "mesh/input_error.h"
#include "viewer/pending_output.h"
#include "viewer/solution_grid.h"
#include "viewer/tone_map.h"
#include "viewer/virtual_display.h"

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

/// Display colours (tone-mapped, sRGB) for the cells and, when present, the points.
void add_display_colours(vtkUnstructuredGrid* g, double ev) {
    auto* cd = g->GetCellData();
    const auto B = rgb_values(cd->GetArray("radiosity"));
    std::vector<Rgb> E = cd->GetArray("emission") ? rgb_values(cd->GetArray("emission")) : std::vector<Rgb>(B.size());
    std::vector<double> A(B.size(), 1.0);
    if (auto* a = cd->GetArray("area"))
        for (std::size_t i = 0; i < A.size(); ++i) A[i] = a->GetTuple1(vtkIdType(i));
    const ToneMap tm = ToneMap::automatic(B, E, A, ev);
    auto colours = [&](const std::vector<Rgb>& values) {
        auto c = vtkSmartPointer<vtkUnsignedCharArray>::New();
        c->SetName("display");
        c->SetNumberOfComponents(3);
        c->SetNumberOfTuples(vtkIdType(values.size()));
        for (std::size_t i = 0; i < values.size(); ++i) {
            const auto px = tm(values[i]);
            c->SetTypedTuple(vtkIdType(i), px.data());
        }
        return c;
    };
    cd->AddArray(colours(B));
    if (auto* pb = g->GetPointData()->GetArray("radiosity"); pb && pb->GetNumberOfComponents() == 3)
        g->GetPointData()->AddArray(colours(rgb_values(pb)));
}

std::string picture_extension(const std::filesystem::path& p) {
    std::string ext = p.extension().string();
    for (auto& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
    return ext;
}

std::string scene_name(vtkUnstructuredGrid* g) {
    return field_text(g->GetFieldData(), "scene");
}

void set_camera(vtkRenderer* ren, vtkUnstructuredGrid* g, const std::string& spec) {
    vtkCamera* cam = ren->GetActiveCamera();
    std::string s = spec;
    if (s == "default") s = scene_name(g) == "cornell" ? "cornell" : "auto";
    if (s == "cornell") {
        // The classic front view of the published Cornell box (camera at z = -800 looking in).
        cam->SetPosition(278, 273, -800);
        cam->SetFocalPoint(278, 273, 0);
        cam->SetViewUp(0, 1, 0);
        cam->SetViewAngle(39.0);
    } else if (s == "auto") {
        ren->ResetCamera();
    } else {
        double v[6];
        char sep1, sep2, colon, sep3, sep4;
        std::istringstream in(s);
        if (!(in >> v[0] >> sep1 >> v[1] >> sep2 >> v[2] >> colon >> v[3] >> sep3 >> v[4] >> sep4 >> v[5]) ||
            sep1 != ',' || sep2 != ',' || colon != ':' || sep3 != ',' || sep4 != ',' || !in.eof())
            throw InputError("camera '" + spec + "': expected cornell, auto or x,y,z:tx,ty,tz");
        cam->SetPosition(v[0], v[1], v[2]);
        cam->SetFocalPoint(v[3], v[4], v[5]);
        cam->SetViewUp(0, 1, 0);
        cam->OrthogonalizeViewUp();
    }
    ren->ResetCameraClippingRange();
}

struct Scene3d {
    vtkNew<vtkRenderer> renderer;
    vtkNew<vtkRenderWindow> window;
    vtkNew<vtkDataSetMapper> mapper;
    vtkNew<vtkActor> actor;
    vtkNew<vtkScalarBarActor> bar;
    vtkNew<vtkLookupTable> lut;
    bool luminance = false;

    Scene3d(vtkUnstructuredGrid* g, const RenderOptions& o) {
        if (o.width < 16 || o.height < 16 || o.width > 8192 || o.height > 8192)
            throw InputError("--size must be between 16x16 and 8192x8192");
        add_display_colours(g, o.exposure);
        mapper->SetInputData(g);
        actor->SetMapper(mapper);
        // Radiosity is view-independent light: no shading on top of it.
        actor->GetProperty()->LightingOff();
        actor->GetProperty()->SetEdgeColor(0.1, 0.1, 0.1);
        actor->GetProperty()->SetEdgeVisibility(o.edges);
        // Colour range from the surfaces that do not emit: a light is orders of magnitude
        // brighter and would flatten everything else into one colour (it saturates instead).
        double range[2] = {0, 0};
        auto* l = g->GetCellData()->GetArray("luminance");
        auto* e = g->GetCellData()->GetArray("emission");
        for (vtkIdType i = 0; l && i < l->GetNumberOfTuples(); ++i) {
            const bool emits = e && (e->GetComponent(i, 0) > 0 || e->GetComponent(i, 1) > 0 || e->GetComponent(i, 2) > 0);
            if (!emits) range[1] = std::max(range[1], l->GetTuple1(i));
        }
        if (!(range[1] > 0)) range[1] = 1;
        lut->SetHueRange(0.667, 0.0);
        lut->SetTableRange(range);
        lut->Build();
        bar->SetLookupTable(lut);
        bar->SetTitle("luminance");
        bar->SetNumberOfLabels(5);
        bar->GetTitleTextProperty()->SetFontSize(14);
        renderer->AddActor(actor);
        renderer->AddActor2D(bar);
        renderer->SetBackground(0.0, 0.0, 0.0);
        window->AddRenderer(renderer);
        window->SetSize(o.width, o.height);
        set_colouring(o.luminance, o.smooth);
        set_camera(renderer, g, o.camera);
    }
    void set_colouring(bool lum, bool smooth) {
        luminance = lum;
        if (lum) {
            mapper->SetScalarModeToUseCellFieldData();
            mapper->SelectColorArray("luminance");
            mapper->SetColorModeToMapScalars();
            mapper->SetLookupTable(lut);
            mapper->UseLookupTableScalarRangeOn();
        } else {
            smooth ? mapper->SetScalarModeToUsePointFieldData() : mapper->SetScalarModeToUseCellFieldData();
            mapper->SelectColorArray("display");
            mapper->SetColorModeToDirectScalars();
        }
        mapper->ScalarVisibilityOn();
        bar->SetVisibility(lum);
    }
};

void render_grid(vtkUnstructuredGrid* g, const std::filesystem::path& png, const RenderOptions& o) {
    check_picture_path(png);
    if (o.smooth && !g->GetPointData()->GetArray("radiosity"))
        throw InputError(png.string() + ": --smooth needs point data 'radiosity' in the input");
    VirtualDisplay display;
    Scene3d s(g, o);
    s.window->SetOffScreenRendering(1);
    s.window->Render();
    vtkNew<vtkWindowToImageFilter> grab;
    grab->SetInput(s.window);
    grab->ReadFrontBufferOff();
    grab->Update();
    std::filesystem::path tmp = png;
    tmp += ".tmp-" + std::to_string(::getpid()) + ".png";
    const PendingOutput pending(tmp.c_str());
    // The format follows the name: a .jpg holding PNG bytes confuses every viewer.
    const bool jpeg = picture_extension(png) != ".png";
    vtkSmartPointer<vtkImageWriter> writer;
    if (jpeg) {
        auto j = vtkSmartPointer<vtkJPEGWriter>::New();
        j->SetQuality(95);
        writer = j;
    } else {
        writer = vtkSmartPointer<vtkPNGWriter>::New();
    }
    writer->SetFileName(tmp.string().c_str());
    writer->SetInputConnection(grab->GetOutputPort());
    writer->Write();
    commit_output(tmp, png, writer->GetErrorCode() == 0 && std::filesystem::exists(tmp), jpeg ? "JPEG" : "PNG");
}

void keypress(vtkObject* caller, unsigned long, void* client, void*) {
    auto* iren = static_cast<vtkRenderWindowInteractor*>(caller);
    auto* s = static_cast<Scene3d*>(client);
    const std::string key = iren->GetKeySym() ? iren->GetKeySym() : "";
    if (key == "e") s->actor->GetProperty()->SetEdgeVisibility(!s->actor->GetProperty()->GetEdgeVisibility());
    if (key == "l") s->set_colouring(!s->luminance, false);
    iren->Render();
}

void timer_exit(vtkObject* caller, unsigned long, void*, void*) {
    static_cast<vtkRenderWindowInteractor*>(caller)->TerminateApp();
}

void view_grid(vtkUnstructuredGrid* g, const RenderOptions& o, double exit_after) {
    VirtualDisplay display;
    Scene3d s(g, o);
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

void render_vtu(const std::filesystem::path& vtu, const std::filesystem::path& png, const RenderOptions& options) {
    render_grid(read_solution_grid(vtu), png, options);
}

void render_solution(const PatchMesh& mesh, const SolveResult& result, const ExportInfo& info,
                     const std::filesystem::path& png, const RenderOptions& options) {
    render_grid(make_solution_grid(mesh, result, info), png, options);
}

void view_vtu(const std::filesystem::path& vtu, const RenderOptions& options, double exit_after) {
    view_grid(read_solution_grid(vtu), options, exit_after);
}

void view_solution(const PatchMesh& mesh, const SolveResult& result, const ExportInfo& info,
                   const RenderOptions& options, double exit_after) {
    view_grid(make_solution_grid(mesh, result, info), options, exit_after);
}

}  // namespace bounce
