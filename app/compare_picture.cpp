// SPDX-License-Identifier: MIT
#include "app/compare_picture.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <optional>
#include <sstream>

#include <tbb/parallel_for.h>

#include "app/progress_line.h"
#include "app/reference_image.h"
#include "app/signals.h"
#include "app/two_pass_render.h"
#include "mesh/meshing/patch_mesh.h"
#include "mesh/readers/scene_loader.h"
#include "mesh/scene/errors.h"
#include "mesh/scene/input_error.h"
#include "solver/reference/path_tracer.h"
#include "solver/two_pass/caustic_check.h"
#include "solver/two_pass/caustic_map.h"
#include "solver/two_pass/patch_scene_tracer.h"
#include "viewer/charts.h"
#include "viewer/eye_picture.h"
#include "viewer/pending_output.h"

namespace bounce::app {
namespace {

constexpr int kMaskRays = 8;  // centre rays per pixel that decide whether it shows a diffuse surface

double since(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

/// The scored pixels: every one of kMaskRays rays through the pixel's centre ends its mirror
/// and glass chain on a non-emitting diffuse surface (glass reflects or refracts at random, so
/// a pixel that may show the lamp, or nothing, is left out).
std::vector<char> diffuse_pixels(const PathTracer& tracer, const PixelRays& rays, int W, int H, std::uint64_t seed) {
    const Scene& scene = tracer.scene();
    std::vector<char> mask(std::size_t(W) * std::size_t(H), 0);
    tbb::parallel_for(0, H, [&](int row) {
        for (int col = 0; col < W; ++col) {
            const std::size_t i = std::size_t(row) * std::size_t(W) + std::size_t(col);
            const glm::dvec3 centre = rays.corner(col, row) + 0.5 * rays.du + 0.5 * rays.dv;
            bool diffuse = true;
            for (int k = 0; k < kMaskRays && diffuse; ++k) {
                const PixelSample s = tracer.pixel_sample(rays.origin, centre, glm::dvec3(0.0), glm::dvec3(0.0), seed,
                                                          i * kMaskRays + std::size_t(k));
                diffuse =
                    s.surface >= 0 &&
                    scene.materials[std::size_t(scene.surfaces[std::size_t(s.surface)].material)].emission.max() <= 0;
            }
            mask[i] = diffuse ? 1 : 0;
        }
    });
    return mask;
}

/// What the score divides each scored pixel's error by: the mean reference luminance over the
/// scored pixels of its 3 x 3 neighbourhood (`own`: the pixel's own). A pixel's own reference
/// value carries the path tracer's noise, and a ratio with a noisy denominator is biased
/// (E[1/Y] > 1/E[Y], by about the relative variance: 1.8% on the ceiling at 2048 paths a
/// pixel); a mean of nine has a ninth of that variance, and the numerator, linear in the
/// reference, keeps the noise's share exact to take out.
std::vector<double> denominators(const std::vector<Rgb>& reference, const std::vector<char>& mask, int W, int H,
                                 bool own) {
    std::vector<double> out(reference.size(), 0.0);
    for (int row = 0; row < H; ++row)
        for (int col = 0; col < W; ++col) {
            const std::size_t i = std::size_t(row) * std::size_t(W) + std::size_t(col);
            if (!mask[i] || own) {
                out[i] = reference[i].luminance();
                continue;
            }
            double sum = 0;
            int n = 0;
            for (int r = std::max(0, row - 1); r <= std::min(H - 1, row + 1); ++r)
                for (int c = std::max(0, col - 1); c <= std::min(W - 1, col + 1); ++c) {
                    const std::size_t j = std::size_t(r) * std::size_t(W) + std::size_t(c);
                    if (mask[j]) sum += reference[j].luminance(), ++n;
                }
            out[i] = sum / n;
        }
    return out;
}

/// sqrt(mean over the scored pixels of ((Y - Y_ref) / D)^2), Y the luminance (Rec. 709) and D
/// from denominators().
double relative_rms(const std::vector<Rgb>& picture, const std::vector<Rgb>& reference,
                    const std::vector<double>& denominator, const std::vector<char>& mask) {
    double sum = 0;
    std::size_t n = 0;
    for (std::size_t i = 0; i < mask.size(); ++i) {
        if (!mask[i] || !(reference[i].luminance() > 0) || !(denominator[i] > 0)) continue;
        const double e = (picture[i].luminance() - reference[i].luminance()) / denominator[i];
        sum += e * e;
        ++n;
    }
    return n > 0 ? std::sqrt(sum / double(n)) : 0.0;
}

/// A score: the error against the reference (denominators from the 3 x 3 neighbourhood) and
/// against each pixel's own reference value, the measure of earlier studies.
struct Score {
    double error = 0, own = 0;
};

double less(double error, double noise) { return std::sqrt(std::max(0.0, error * error - noise * noise)); }

/// Scores pictures against the reference over the scored pixels.
struct Scorer {
    const std::vector<Rgb>& reference;
    const std::vector<char>& mask;
    std::vector<double> near, own;  // denominators()
    Scorer(const std::vector<Rgb>& ref, const std::vector<char>& m, int W, int H)
        : reference(ref), mask(m), near(denominators(ref, m, W, H, false)), own(denominators(ref, m, W, H, true)) {}
    Score operator()(const std::vector<Rgb>& picture) const {
        return {relative_rms(picture, reference, near, mask), relative_rms(picture, reference, own, mask)};
    }
};

/// The path tracer's picture for a wall time: rounds of one path per pixel (pixel_sample,
/// uniformly over the pixel) until `seconds` have passed since it began, at least one round.
struct Progressive {
    EyeImage image;
    std::uint64_t rounds = 0;
    double seconds = 0;
};

Progressive path_trace_for(const Scene& scene, const PixelRays& rays, int W, int H, double seconds,
                           std::uint64_t seed) {
    const auto start = std::chrono::steady_clock::now();
    const PathTracer tracer(scene);
    const std::size_t n = std::size_t(W) * std::size_t(H);
    std::vector<Rgb> sum(n);
    Progressive out;
    do {
        const std::uint64_t round = out.rounds;
        tbb::parallel_for(0, H, [&](int row) {
            for (int col = 0; col < W; ++col) {
                const std::size_t i = std::size_t(row) * std::size_t(W) + std::size_t(col);
                sum[i] += tracer.pixel_sample(rays.origin, rays.corner(col, row), rays.du, rays.dv, seed, round * n + i)
                              .radiance;
            }
        });
        ++out.rounds;
    } while (since(start) < seconds && !g_interrupted.load());
    out.image.width = W;
    out.image.height = H;
    out.image.rows_done = std::size_t(H);
    out.image.pixels.resize(n);
    for (std::size_t i = 0; i < n; ++i) out.image.pixels[i] = sum[i] * (1.0 / double(out.rounds));
    out.seconds = since(start);
    return out;
}

/// One row of picture.csv.
struct Row {
    std::string method;
    std::size_t budget = 0;
    double seconds = 0;
    std::size_t patches = 0;  // two-pass: patches of the light pass
    int samples = 0;          // two-pass: eye rays per pixel
    std::size_t photons = 0;  // two-pass: per light-pass round
    std::uint64_t paths = 0;  // path tracer: paths per pixel
    Score error;
};

/// The long path-traced image and its per-pixel standard error, from the cache in `dir` or made
/// by `bounce reference --image` and left there.
std::vector<Rgb> reference_image(const CommonOptions& o, const ComparePictureOptions& p, const std::string& scene,
                                 const std::filesystem::path& dir, std::vector<Rgb>& standard_error) {
    std::ostringstream name;
    name << "reference_" << std::filesystem::path(scene).stem().string() << "_" << p.width << "x" << p.height << "_"
         << p.reference_paths << ".pfm";
    ReferenceImageOptions r;
    r.output = (dir / name.str()).string();
    r.camera.width = p.width;
    r.camera.height = p.height;
    r.paths = p.reference_paths;
    r.seed = p.seed + 2;
    std::filesystem::path se = r.output;
    se.replace_filename(std::filesystem::path(r.output).stem().string() + "_se.pfm");
    if (!std::filesystem::exists(r.output) || !std::filesystem::exists(se)) {
        CommonOptions ro = o;
        ro.scene = scene;
        if (!o.quiet)
            std::cerr << "compare --picture: the long path-traced image, once (cached in " << dir.string() << ")\n";
        if (run_reference_image(ro, r) != 0) {
            // Interrupted: the rows done are no reference to cache.
            std::filesystem::remove(r.output);
            std::filesystem::remove(se);
            throw Interrupted("interrupted while path tracing the reference");
        }
    }
    int w = 0, h = 0, ws = 0, hs = 0;
    std::vector<Rgb> image = read_pfm(r.output, w, h);
    standard_error = read_pfm(se, ws, hs);
    if (w != p.width || h != p.height || ws != w || hs != h)
        throw InputError(r.output + ": cached reference of another size; remove it");
    return image;
}

void write_rows(const std::filesystem::path& csv, const std::vector<Row>& rows, const std::string& scene,
                const ComparePictureOptions& p, std::size_t pixels, const Score& noise) {
    write_text_file(
        csv,
        [&](std::ostream& out) {
            out << "scene,size,method,budget,seconds,patches,samples_per_pixel,photons,paths_per_pixel,rms_error,"
                   "pixels,reference_paths,reference_noise,rms_error_less_noise,rms_error_own,reference_noise_own,"
                   "rms_error_own_less_noise\n";
            out.precision(6);
            for (const Row& r : rows)
                out << scene << ',' << p.width << 'x' << p.height << ',' << r.method << ',' << r.budget << ','
                    << r.seconds << ',' << r.patches << ',' << r.samples << ',' << r.photons << ',' << r.paths << ','
                    << r.error.error << ',' << pixels << ',' << p.reference_paths << ',' << noise.error << ','
                    << less(r.error.error, noise.error) << ',' << r.error.own << ',' << noise.own << ','
                    << less(r.error.own, noise.own) << '\n';
        },
        "picture comparison");
}

/// cornell-spheres: the caustic under the glass sphere (caustic_check.h) by the emitters'
/// photons of the last budget's light pass and by the path tracer, in caustic.csv and on the
/// terminal: the power landing within 50 mm of it and the pixel where it peaks.
void report_caustic(const CommonOptions& o, const ComparePictureOptions& p, const Scene& scene, const PatchMesh& mesh,
                    const PinholeCamera& camera, const std::filesystem::path& dir) {
    const PatchSceneTracer tracer(scene, mesh);
    CausticOptions co;
    co.photons = p.photons.back();
    co.seed = p.seed;
    const CausticMap map(mesh, tracer, co, &g_interrupted);
    const CausticRegion region = cornell_spheres_caustic_region();
    const CausticView view{camera, p.width, p.height};
    const CausticMeasure photons = measure_caustic(map, region, view);
    TracedCausticOptions to;
    to.emitted_only = true;
    to.region_points = 16384;
    to.pixel_points = 64;
    to.seed = p.seed;
    const CausticMeasure traced = measure_caustic(PathTracer(scene), region, view, to);
    if (g_interrupted.load()) throw Interrupted("interrupted");
    write_text_file(
        dir / "caustic.csv",
        [&](std::ostream& out) {
            out << "method,photons,power,power_se,peak_col,peak_row,peak,peak_se\n";
            for (const auto* m : {&photons, &traced})
                out << (m == &photons ? "photon map," + std::to_string(co.photons) : std::string("path tracer,")) << ','
                    << m->power.luminance() << ',' << m->power_se.luminance() << ',' << m->peak_col << ','
                    << m->peak_row << ',' << m->peak << ',' << m->peak_se << '\n';
        },
        "caustic comparison");
    if (!o.quiet)
        std::printf(
            "caustic under the glass sphere: photon map (%zu photons) %.0f W, path tracer %.0f +- %.0f W (ratio "
            "%.3f); peak at pixel (%d, %d) and (%d, %d)\n",
            co.photons, photons.power.luminance(), traced.power.luminance(), traced.power_se.luminance(),
            photons.power.luminance() / traced.power.luminance(), photons.peak_col, photons.peak_row, traced.peak_col,
            traced.peak_row);
}

}  // namespace

std::shared_ptr<ComparePictureOptions> add_compare_picture_options(CLI::App* compare) {
    auto p = std::make_shared<ComparePictureOptions>();
    p->scene = compare->get_option_no_throw("scene");
    auto* flag = compare->add_flag("--picture", p->enabled,
                                   "instead of solvers: the two-pass picture against the path tracer at equal time, "
                                   "scored against a long path-traced image (scene default: cornell-spheres)");
    if (auto* meshes = compare->get_option_no_throw("--meshes")) flag->excludes(meshes);
    compare
        ->add_option(
            "--picture-size",
            [p](const CLI::results_t& v) {
                char end = 0;
                return std::sscanf(v[0].c_str(), "%dx%d%c", &p->width, &p->height, &end) == 2 && p->width >= 16 &&
                       p->height >= 16 && p->width <= 4096 && p->height <= 4096;
            },
            "--picture: WxH, 16 to 4096 each (512x512)")
        ->needs(flag);
    compare
        ->add_option("--picture-patches", p->patches,
                     "--picture: patches of the two-pass light pass, one per time budget (as --patches)")
        ->delimiter(',')
        ->check(in_range(std::size_t(1), std::size_t(1000000)))
        ->capture_default_str()
        ->needs(flag);
    compare->add_option("--picture-samples", p->samples, "--picture: two-pass eye rays per pixel, one per time budget")
        ->delimiter(',')
        ->check(CLI::Range(1, 4096))
        ->capture_default_str()
        ->needs(flag);
    compare
        ->add_option("--picture-photons", p->photons,
                     "--picture: two-pass photons of the emitters (as render's --photons), one per time budget")
        ->delimiter(',')
        ->capture_default_str()
        ->needs(flag);
    compare
        ->add_option("--reference-paths", p->reference_paths,
                     "--picture: paths per pixel of the long path-traced image (cached in the output folder)")
        ->check(in_range(std::uint64_t(64), std::uint64_t(1) << 30))
        ->capture_default_str()
        ->needs(flag);
    return p;
}

int run_compare_picture(const CommonOptions& o, const ComparePictureOptions& p, const std::string& out) {
    if (p.samples.size() != p.photons.size() || p.samples.size() != p.patches.size() || p.samples.empty())
        throw InputError(
            "--picture-patches, --picture-samples and --picture-photons: one value each per time budget, "
            "got " +
            std::to_string(p.patches.size()) + ", " + std::to_string(p.samples.size()) + " and " +
            std::to_string(p.photons.size()));
    const std::string spec = p.scene && p.scene->count() > 0 ? o.scene : "cornell-spheres";
    const std::filesystem::path dir = out;
    std::filesystem::create_directories(dir);
    check_output(dir / "picture.csv");
    CommonOptions quiet = o;
    quiet.quiet = true;

    RenderOptions camera;
    camera.width = p.width;
    camera.height = p.height;
    std::vector<Rgb> se;
    const std::vector<Rgb> reference = reference_image(o, p, spec, dir, se);

    const Scene scene = load_scene(spec, LoadOptions{o.flip, o.strict, {}});
    const PinholeCamera view = scene_camera(scene, camera);
    const PixelRays rays = pixel_rays(view, p.width, p.height);
    const std::vector<char> mask = diffuse_pixels(PathTracer(scene), rays, p.width, p.height, p.seed + 3);
    std::size_t pixels = 0;
    for (const char m : mask) pixels += m ? 1 : 0;
    // The reference's own noise in the score's measure: a picture equal to the truth scores
    // about this against it.
    const Scorer score(reference, mask, p.width, p.height);
    std::vector<Rgb> one_se(reference);
    for (std::size_t i = 0; i < one_se.size(); ++i) one_se[i] += Rgb::gray(se[i].luminance());
    const Score noise = score(one_se);

    ProgressLine progress(!o.quiet);
    std::vector<Row> rows;
    std::optional<TwoPassPicture> two_pass;
    std::optional<PatchMesh> mesh;
    std::optional<Progressive> traced;
    const std::size_t budgets = p.samples.size();
    for (std::size_t k = 0; k < budgets; ++k) {
        progress.runs("compare --picture", 2 * k, 2 * budgets,
                      "two-pass, " + std::to_string(p.samples[k]) + " rays a pixel, " + std::to_string(p.photons[k]) +
                          " photons");
        const auto start = std::chrono::steady_clock::now();
        CommonOptions level = quiet;
        level.meshing.target_patches = p.patches[k];
        Scene loaded;
        mesh.emplace(load_and_mesh(level, spec, loaded));
        TwoPassOptions t;
        t.samples = p.samples[k];
        t.photons = p.photons[k];
        t.seed = p.seed;
        two_pass.emplace(render_two_pass(level, loaded, *mesh, camera, t));
        if (g_interrupted.load() || !two_pass->image.complete()) throw Interrupted("interrupted");
        const double seconds = since(start);
        rows.push_back(
            {"two-pass", k + 1, seconds, mesh->size(), t.samples, t.photons, 0, score(two_pass->image.pixels)});
        progress.runs("compare --picture", 2 * k + 1, 2 * budgets, "path tracer, " + std::to_string(seconds) + " s");
        traced.emplace(path_trace_for(scene, rays, p.width, p.height, seconds, p.seed + 10 + k));
        if (g_interrupted.load()) throw Interrupted("interrupted");
        rows.push_back({"path tracer", k + 1, traced->seconds, 0, 0, 0, traced->rounds, score(traced->image.pixels)});
    }
    progress.finish();
    write_rows(dir / "picture.csv", rows, spec, p, pixels, noise);
    write_picture_chart(dir);
    const EyeImage ref{p.width, p.height, reference, std::size_t(p.height)};
    write_eye_pictures({&two_pass->image, &traced->image, &ref}, *mesh, two_pass->shown, 0.0,
                       dir / "picture_side_by_side.png");
    if (!o.quiet) {
        std::printf(
            "%s, %dx%d: relative RMS luminance error at %zu pixels on diffuse surfaces, against %llu paths a "
            "pixel (its own noise %.2f%%; %.2f%% over each pixel's own value)\n",
            spec.c_str(), p.width, p.height, pixels, (unsigned long long)p.reference_paths, 100 * noise.error,
            100 * noise.own);
        std::printf("%-7s %-12s %9s %8s %14s %10s %12s %12s\n", "budget", "method", "seconds", "patches", "per pixel",
                    "error", "less noise", "(own pixel)");
        for (const Row& r : rows)
            std::printf(
                "%-7zu %-12s %9.2f %8zu %14s %9.2f%% %11.2f%% %11.2f%%\n", r.budget, r.method.c_str(), r.seconds,
                r.patches,
                (r.method == "two-pass" ? std::to_string(r.samples) + " rays" : std::to_string(r.paths) + " paths")
                    .c_str(),
                100 * r.error.error, 100 * less(r.error.error, noise.error), 100 * less(r.error.own, noise.own));
    }
    if (spec == "cornell-spheres") report_caustic(o, p, scene, *mesh, view, dir);
    if (!o.quiet) {
        std::cout << "wrote " << (dir / "picture.csv").string()
                  << ", picture_error.png and picture_side_by_side.png (two-pass | path tracer | reference)"
                  << (spec == "cornell-spheres" ? ", caustic.csv\n" : "\n");
    }
    return 0;
}

}  // namespace bounce::app
