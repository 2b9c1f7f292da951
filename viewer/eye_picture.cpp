// SPDX-License-Identifier: MIT
#include "viewer/eye_picture.h"

#include <unistd.h>

#include <algorithm>
#include <fstream>
#include <numbers>

#include <vtkImageData.h>
#include <vtkPointData.h>
#include <vtkSmartPointer.h>
#include <vtkUnsignedCharArray.h>

#include "mesh/scene/input_error.h"
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

std::vector<Rgb> read_pfm(const std::filesystem::path& path, int& width, int& height) {
    std::ifstream in(path, std::ios::binary);
    std::string magic;
    double scale = 0;
    if (!(in >> magic >> width >> height >> scale) || magic != "PF" || width <= 0 || height <= 0 || scale >= 0 ||
        width > 65536 || height > 65536)
        throw InputError(path.string() + ": not a little-endian RGB .pfm");
    in.get();  // the single whitespace before the data
    std::vector<Rgb> pixels(std::size_t(width) * std::size_t(height));
    std::vector<float> row(3 * std::size_t(width));
    for (int r = height - 1; r >= 0; --r) {
        if (!in.read(reinterpret_cast<char*>(row.data()), std::streamsize(row.size() * sizeof(float))))
            throw InputError(path.string() + ": .pfm shorter than its " + std::to_string(width) + " x " +
                             std::to_string(height) + " pixels");
        for (int c = 0; c < width; ++c)
            pixels[std::size_t(r) * std::size_t(width) + std::size_t(c)] = {
                row[3 * std::size_t(c)], row[3 * std::size_t(c) + 1], row[3 * std::size_t(c) + 2]};
    }
    return pixels;
}

void write_eye_pictures(const std::vector<const EyeImage*>& images, const PatchMesh& mesh, const SolveResult& result,
                        double exposure, const std::filesystem::path& picture) {
    check_picture_path(picture);
    std::vector<Rgb> emission;
    std::vector<double> area;
    for (const auto& p : mesh.patches()) {
        emission.push_back(p.emission);
        area.push_back(p.area);
    }
    const ToneMap tone = ToneMap::automatic(result.radiosity, emission, area, exposure);
    constexpr int kGap = 4;  // black pixels between pictures
    int width = 0, height = 0;
    for (const EyeImage* im : images) {
        width += im->width + (width > 0 ? kGap : 0);
        height = std::max(height, im->height);
    }
    auto data = vtkSmartPointer<vtkImageData>::New();
    data->SetDimensions(width, height, 1);
    data->AllocateScalars(VTK_UNSIGNED_CHAR, 3);
    auto* out = static_cast<unsigned char*>(data->GetScalarPointer());
    std::fill(out, out + 3 * std::size_t(width) * std::size_t(height), 0);
    int left = 0;
    for (const EyeImage* im : images) {
        for (int row = 0; row < im->height; ++row)
            for (int col = 0; col < im->width; ++col) {
                // VTK's images run bottom to top.
                const Rgb& L = im->pixels[std::size_t(row) * std::size_t(im->width) + std::size_t(col)];
                const auto c = tone(L * std::numbers::pi);
                unsigned char* px =
                    out + 3 * (std::size_t(height - 1 - row) * std::size_t(width) + std::size_t(left + col));
                px[0] = c[0];
                px[1] = c[1];
                px[2] = c[2];
            }
        left += im->width + kGap;
    }
    write_picture(data, picture);
}

void write_eye_picture(const EyeImage& image, const PatchMesh& mesh, const SolveResult& result, double exposure,
                       const std::filesystem::path& picture) {
    if (is_linear_picture(picture)) return write_linear_picture(picture, image.width, image.height, image.pixels);
    write_eye_pictures({&image}, mesh, result, exposure, picture);
}

}  // namespace bounce
