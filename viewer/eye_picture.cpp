// SPDX-License-Identifier: MIT
#include "viewer/eye_picture.h"

#include <unistd.h>

#include <fstream>
#include <numbers>

#include <vtkImageData.h>
#include <vtkPointData.h>
#include <vtkSmartPointer.h>
#include <vtkUnsignedCharArray.h>

#include "viewer/camera.h"
#include "viewer/exr_writer.h"
#include "viewer/pending_output.h"
#include "viewer/picture_writer.h"
#include "viewer/solution_grid.h"
#include "viewer/tone_map.h"

namespace bounce {

PinholeCamera eye_camera(const PatchMesh& mesh, const SolveResult& result, const ExportInfo& info,
                         const RenderOptions& options) {
    const auto grid = make_solution_grid(mesh, result, info);
    std::string spec = options.camera;
    if (spec == "default" && (info.scene == "cornell" || info.scene == "cornell-spheres")) spec = "cornell";
    const CameraPose pose = choose_camera(grid, spec, options.fov, double(options.width) / options.height,
                                          options.camera_name, options.fov_name);
    PinholeCamera cam;
    cam.position = {pose.position[0], pose.position[1], pose.position[2]};
    cam.target = {pose.focal_point[0], pose.focal_point[1], pose.focal_point[2]};
    cam.up = {pose.view_up[0], pose.view_up[1], pose.view_up[2]};
    cam.vertical_fov = pose.view_angle;
    return cam;
}

void write_pfm(const std::filesystem::path& path, int width, int height, const std::vector<Rgb>& pixels) {
    std::filesystem::path tmp = path;
    tmp += ".tmp-" + std::to_string(::getpid()) + ".pfm";
    const PendingOutput pending(tmp.c_str());
    bool ok = false;
    {
        std::ofstream out(tmp, std::ios::binary);
        // A negative scale says little-endian; rows run bottom to top.
        out << "PF\n" << width << " " << height << "\n-1.0\n";
        std::vector<float> row(3 * std::size_t(width));
        for (int r = height - 1; r >= 0; --r) {
            for (int c = 0; c < width; ++c) {
                const Rgb& L = pixels[std::size_t(r) * std::size_t(width) + std::size_t(c)];
                for (int k = 0; k < 3; ++k) row[3 * std::size_t(c) + std::size_t(k)] = float(L[k]);
            }
            out.write(reinterpret_cast<const char*>(row.data()), std::streamsize(row.size() * sizeof(float)));
        }
        ok = bool(out);
    }
    commit_output(tmp, path, ok, "PFM picture");
}

void write_eye_picture(const EyeImage& image, const PatchMesh& mesh, const SolveResult& result, double exposure,
                       const std::filesystem::path& picture) {
    if (is_linear_picture(picture)) return write_linear_picture(picture, image.width, image.height, image.pixels);
    check_picture_path(picture);
    std::vector<Rgb> emission;
    std::vector<double> area;
    for (const auto& p : mesh.patches()) {
        emission.push_back(p.emission);
        area.push_back(p.area);
    }
    const ToneMap tone = ToneMap::automatic(result.radiosity, emission, area, exposure);
    auto data = vtkSmartPointer<vtkImageData>::New();
    data->SetDimensions(image.width, image.height, 1);
    data->AllocateScalars(VTK_UNSIGNED_CHAR, 3);
    auto* out = static_cast<unsigned char*>(data->GetScalarPointer());
    for (int row = 0; row < image.height; ++row)
        for (int col = 0; col < image.width; ++col) {
            // VTK's images run bottom to top.
            const Rgb& L = image.pixels[std::size_t(row) * std::size_t(image.width) + std::size_t(col)];
            const auto c = tone(L * std::numbers::pi);
            unsigned char* px =
                out + 3 * (std::size_t(image.height - 1 - row) * std::size_t(image.width) + std::size_t(col));
            px[0] = c[0];
            px[1] = c[1];
            px[2] = c[2];
        }
    write_picture(data, picture);
}

}  // namespace bounce
