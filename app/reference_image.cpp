// SPDX-License-Identifier: MIT
#include "app/reference_image.h"

#include <atomic>
#include <chrono>
#include <cmath>
#include <iostream>
#include <numbers>

#include <tbb/parallel_for.h>
#include <glm/geometric.hpp>

#include "app/progress_line.h"
#include "app/signals.h"
#include "mesh/meshing/patch_mesh.h"
#include "mesh/readers/scene_loader.h"
#include "mesh/scene/input_error.h"
#include "solver/reference/path_tracer.h"
#include "viewer/exr_writer.h"
#include "viewer/eye_picture.h"
#include "viewer/pending_output.h"

namespace bounce::app {

PinholeCamera scene_camera(const Scene& scene, const RenderOptions& camera) {
    MeshingOptions whole;
    whole.subdivide = false;
    const PatchMesh faces(scene, whole);
    SolveResult none;
    none.radiosity.assign(faces.size(), Rgb());
    return eye_camera(faces, none, {scene.name, "", false, scene.units}, camera);
}

PixelRays pixel_rays(const PinholeCamera& cam, int width, int height) {
    const glm::dvec3 w = glm::normalize(cam.target - cam.position);
    const glm::dvec3 u = glm::normalize(glm::cross(w, cam.up));
    const glm::dvec3 v = glm::cross(u, w);
    const double half_h = std::tan(0.5 * cam.vertical_fov * std::numbers::pi / 180.0);
    const double half_w = half_h * double(width) / double(height);
    PixelRays r;
    r.origin = cam.position;
    r.du = (2 * half_w / width) * u;
    r.dv = -(2 * half_h / height) * v;
    r.top_left = w - half_w * u + half_h * v;
    return r;
}

int run_reference_image(const CommonOptions& o, const ReferenceImageOptions& r) {
    const std::filesystem::path out(r.output);
    if (!is_linear_picture(out))
        throw InputError(r.output + ": reference image format, got '" + out.extension().string() +
                         "' (expected .pfm or .exr, linear radiance)");
    if (!(r.camera.width > 0 && r.camera.height > 0))
        throw InputError("--size: picture size, got " + std::to_string(r.camera.width) + "x" +
                         std::to_string(r.camera.height) + " (expected positive WxH)");
    std::filesystem::path se_path = out;
    se_path.replace_filename(out.stem().string() + "_se" + out.extension().string());
    check_output(out);
    const auto start = std::chrono::steady_clock::now();
    const Scene scene = load_scene(o.scene, LoadOptions{o.flip, o.strict, {}});
    const PathTracer tracer(scene);
    const int W = r.camera.width, H = r.camera.height;
    const PixelRays rays = pixel_rays(scene_camera(scene, r.camera), W, H);

    std::vector<Rgb> radiance(std::size_t(W) * std::size_t(H)), error(radiance.size());
    std::atomic<std::size_t> done{0};
    ProgressLine progress(!o.quiet);
    tbb::parallel_for(0, H, [&](int row) {
        if (g_interrupted.load(std::memory_order_relaxed)) return;
        for (int col = 0; col < W; ++col) {
            const std::size_t i = std::size_t(row) * std::size_t(W) + std::size_t(col);
            const auto e =
                tracer.pixel_radiance(rays.origin, rays.corner(col, row), rays.du, rays.dv, r.paths, r.seed, i);
            radiance[i] = e.radiance;
            error[i] = e.standard_error;
        }
        progress.items("path tracing: rows", ++done, std::size_t(H));
    });
    progress.finish();
    write_linear_picture(out, W, H, radiance);
    write_linear_picture(se_path, W, H, error);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (!o.quiet) {
        std::cout << W << " x " << H << " pixels, " << r.paths << " paths each, in " << seconds << " s\n";
        std::cout << "wrote " << out.string() << " and " << se_path.string() << "\n";
    }
    if (done.load() < std::size_t(H)) {
        std::cerr << "bounce: interrupted: " << out.string() << " holds the " << done.load() << " of " << H
                  << " rows done (the rest black)\n";
        return interrupted_exit_code() ? interrupted_exit_code() : 130;
    }
    return 0;
}

}  // namespace bounce::app
