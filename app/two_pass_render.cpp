// SPDX-License-Identifier: MIT
#include "app/two_pass_render.h"

#include <algorithm>
#include <chrono>
#include <iostream>
#include <memory>
#include <optional>

#include "app/progress_line.h"
#include "app/signals.h"
#include "mesh/meshing/patch_mesh.h"
#include "mesh/scene/errors.h"
#include "mesh/scene/input_error.h"
#include "solver/pipeline/solve_scene.h"
#include "solver/two_pass/caustic_map.h"
#include "solver/two_pass/eye_pass.h"
#include "solver/two_pass/patch_scene_tracer.h"
#include "solver/two_pass/spread_photon_light.h"
#include "viewer/eye_picture.h"
#include "viewer/pending_output.h"

namespace bounce::app {

void add_two_pass_options(CLI::App* cmd, TwoPassOptions& t) {
    cmd->add_flag("--ray-trace", t.ray_trace,
                  "draw by eye rays over the radiosity (the default for scenes with mirrors or glass)");
    cmd->add_option("--samples", t.samples, "eye rays: rays per pixel, jittered (16)")->check(CLI::Range(1, 4096));
    cmd->add_option(
        "--photons", t.photons,
        "eye rays: photons of the emitters in the light pass; later rounds as many as carry as much power each "
        "(2000000; 0: none)");
    cmd->add_option(
           "--photon-rounds", t.rounds,
           "eye rays: photon rounds: the emitters', then the patches' light not yet sent through mirrors and glass (3)")
        ->check(CLI::Range(1, 16));
    cmd->add_option("--photon-nearest", t.nearest,
                    "eye rays: photons per caustic radiance estimate (32; 0: all within --photon-radius)");
    cmd->add_option("--photon-radius", t.photon_radius,
                    "eye rays: largest caustic estimate radius in scene units (0: 2% of the scene's diagonal)")
        ->check(CLI::NonNegativeNumber);
    cmd->add_option("--max-depth", t.max_depth, "eye rays: mirror and glass bounces per ray (16)")
        ->check(CLI::Range(0, 1000));
    cmd->add_option("--seed", t.seed, "eye rays: seed of the jitter and the photons (1)");
    cmd->add_option("--display-tolerance", t.display_tolerance,
                    "eye rays: display cells of the light pass's point data, as solve's (0.02; 0: off)")
        ->check(CLI::Range(0.0, 1.0));
}

namespace {

// The diverging photons' estimate (spread_photon_light.h): photons per estimate and the
// largest radius, as a share of the scene's diagonal. Their light is smooth, so wide.
constexpr std::size_t kSpreadNearest = 512;
constexpr double kSpreadRadius = 0.05;

/// The light pass: the radiosity of the diffuse patches with the caustic photons' power handed
/// to the patches they reach, the caustic map, and the point data the eye pass interpolates.
struct LightPass {
    SolveResult res;
    std::vector<Rgb> caustic_radiosity;      // rho Phi / A: the light the photons reflect off each patch
    std::unique_ptr<CausticMap> caustics;    // the photons the eye pass estimates from; none without photons
    std::unique_ptr<CausticMap> spread;      // the diverging photons, estimated at the vertices
    SolveResult shown;                       // res over the patches, less the caustic term: the picture's exposure
    std::shared_ptr<const PatchMesh> cells;  // the mesh the point data is over: the patches or their display cells
    std::vector<Rgb> vertex, patch_values;   // B per vertex (without the caustic term) and per cell of `cells`
    std::size_t emitted = 0;
    double specular_first = 0;
};

LightPass light_pass(const CommonOptions& o, const Scene& scene, const PatchMesh& mesh, const TwoPassOptions& t) {
    const auto& P = mesh.patches();
    const PatchSceneTracer tracer(scene, mesh);
    LightPass lp;
    // Mirrors and glass occlude the radiosity's form factors; photons carry the light they
    // redirect and hand it to the patches where it lands (rho Phi / A, added to the patches'
    // emission for the solve, so the solution carries it on). Round 1: photons from the
    // emitters (L S+ D). Rounds 2 and on, each after a solve: photons from every patch with
    // reflected radiosity (L D+ S+ D: a wall seen in the mirror lights the floor), then the
    // solve again with them all.
    const bool photons = t.photons > 0 && scene.has_specular();
    CausticOptions co;
    co.photons = t.photons;
    co.radius = t.photon_radius;
    co.nearest = t.nearest;
    co.seed = t.seed;
    lp.caustic_radiosity.assign(P.size(), Rgb());
    double radius = 0;
    // The photons whose light may land focused or sharp-edged go to the eye pass's map; the
    // rest to a wide estimate at the point data's vertices (spread_photon_light.h): those turned
    // only by the outsides of spheres (CausticPhoton::diverging), and all of a patch round,
    // whose sources are the lit walls: a sphere images a source that wide as a wide blur.
    std::vector<CausticPhoton> stored, spread;
    auto add_photons = [&](const CausticMap& map, bool from_patches) {
        const auto power = map.power_per_patch();
        for (std::size_t p = 0; p < P.size(); ++p)
            if (P[p].area > 0) lp.caustic_radiosity[p] += P[p].reflectance * power[p] * (1.0 / P[p].area);
        for (const CausticPhoton& ph : map.photons()) (from_patches || ph.diverging ? spread : stored).push_back(ph);
        lp.emitted += map.emitted();
        radius = map.radius();
    };
    // The radiosity is bounce solve's (solve_scene, shooting with open parts, balanced rows and
    // display cells); between its solves over the same form factors, the photon rounds add the
    // light they hand to the patches (SolveHooks::added_emission).
    SolveRequest request;
    request.meshing = o.meshing;
    request.visibility = o.visibility;
    request.flip = o.flip;
    request.display_tolerance = t.display_tolerance;
    request.validate();
    // Rounds 2 and on: photons from every patch with the reflected radiosity it has not yet
    // sent through mirrors and glass (the first time all of B - E, then what the last solve
    // added), so light that goes through them twice or more is carried too.
    std::vector<Rgb> sent(P.size());
    double emitted_power = 0;
    for (const Patch& patch : P) emitted_power += patch.emission.sum() * patch.area;
    int round = 1;
    ProgressLine progress(!o.quiet);
    SolveHooks hooks;
    hooks.cancel = &g_interrupted;
    hooks.mesh = [&](const MeshingOptions&) {
        return std::shared_ptr<const PatchMesh>(std::shared_ptr<void>(), &mesh);
    };
    hooks.items = [&](const char* stage, std::size_t d, std::size_t n) { progress.items(stage, d, n); };
    hooks.stage_end = [&] { progress.finish(); };
    hooks.added_emission = [&](const SolveResult* so_far) -> std::optional<std::vector<Rgb>> {
        if (!so_far) {
            if (photons) {
                const CausticMap lamps(mesh, tracer, co, &g_interrupted);
                if (g_interrupted.load()) throw Interrupted("interrupted while tracing caustic photons");
                lp.specular_first = lamps.specular_first_share();
                add_photons(lamps, false);
            }
            return lp.caustic_radiosity;
        }
        lp.res = *so_far;
        if (!photons || ++round > t.rounds) return std::nullopt;
        std::vector<Rgb> exitance(P.size());
        for (std::size_t p = 0; p < P.size(); ++p) {
            Rgb reflected = so_far->radiosity[p] - P[p].emission;
            for (int c = 0; c < 3; ++c) exitance[p][c] = std::max(0.0, reflected[c] - sent[p][c]);
            sent[p] += exitance[p];
        }
        co.seed = t.seed + std::uint64_t(round - 1);
        // As many photons as carry the emitters' photon power each: one k-nearest estimate
        // then sums photons of like power whatever round they come from (a few weak photons
        // of a late round among strong ones would only shrink its radius and add noise).
        double power = 0;
        for (std::size_t p = 0; p < P.size(); ++p) power += exitance[p].sum() * P[p].area;
        co.photons = std::size_t(std::min(4.0, power / emitted_power) * double(t.photons));
        if (co.photons == 0) return std::nullopt;
        const CausticMap surfaces(mesh, tracer, co, &g_interrupted, &exitance);
        if (g_interrupted.load()) throw Interrupted("interrupted while tracing caustic photons");
        add_photons(surfaces, true);
        return lp.caustic_radiosity;
    };
    SolvedScene solved = solve_scene(scene, request, hooks);
    if (g_interrupted.load()) throw Interrupted("interrupted while solving the radiosity");
    print_solve_messages(solved, o.quiet);
    if (photons) {
        lp.caustics = std::make_unique<CausticMap>(std::move(stored), radius, P.size(), t.nearest);
        lp.spread = std::make_unique<CausticMap>(std::move(spread), kSpreadRadius * tracer.diagonal(), P.size(),
                                                 kSpreadNearest);
    }
    // The point data, gathered at the vertices from the solved patches: each vertex's own
    // emission is the mesh's (without the caustic term), so the gathered B holds the caustic
    // light only as it arrives from elsewhere; the photon map adds the caustic where it lands.
    // Patches the light bends across are cut into display cells (patch_display_refinement.h),
    // which the eye pass then shows.
    lp.shown = lp.res;
    for (std::size_t p = 0; p < P.size(); ++p) lp.shown.radiosity[p] -= lp.caustic_radiosity[p];
    lp.cells = solved.gathered ? solved.mesh : std::shared_ptr<const PatchMesh>(std::shared_ptr<void>(), &mesh);
    lp.vertex = solved.gathered ? solved.result.point_radiosity : area_weighted_vertex_values(mesh, lp.shown.radiosity);
    if (lp.spread) {
        const auto light = spread_photon_light(*lp.spread, *lp.cells, PatchSceneTracer(scene, *lp.cells));
        for (std::size_t v = 0; v < lp.vertex.size(); ++v) lp.vertex[v] += light[v];
    }
    // Each cell's own value, where its corners' cannot be interpolated: their mean (the
    // cells' solved values hold the caustic term).
    lp.patch_values.assign(lp.cells->size(), Rgb());
    for (std::size_t c = 0; c < lp.cells->size(); ++c) {
        const auto idx = lp.cells->patch_vertex_indices(c);
        for (const int v : idx) lp.patch_values[c] += lp.vertex[std::size_t(v)] * (1.0 / double(idx.size()));
    }
    return lp;
}

}  // namespace

TwoPassPicture render_two_pass(const CommonOptions& o, const Scene& scene, const PatchMesh& mesh,
                               const RenderOptions& render, const TwoPassOptions& t) {
    const auto start = std::chrono::steady_clock::now();
    auto seconds = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); };
    LightPass lp = light_pass(o, scene, mesh, t);
    TwoPassPicture out;
    out.light_seconds = seconds();
    out.shots = lp.res.steps;
    out.emitted = lp.emitted;
    out.specular_first = lp.specular_first;
    out.stored = lp.caustics ? lp.caustics->photons().size() : 0;
    // The exposure as render's for the radiosity alone: the mean non-emitting patch at mid grey.
    out.shown = lp.shown;

    const ExportInfo info{scene.name, "", false, scene.units};
    const PinholeCamera camera = eye_camera(mesh, lp.shown, info, render);
    EyePassOptions eo;
    eo.width = render.width;
    eo.height = render.height;
    eo.samples_per_pixel = t.samples;
    eo.max_depth = t.max_depth;
    eo.seed = t.seed;
    const EyePass pass(scene, *lp.cells, std::move(lp.vertex), std::move(lp.patch_values), lp.caustics.get());
    ProgressLine progress(!o.quiet);
    out.image = pass.render(
        camera, eo, [&](std::size_t d, std::size_t n) { progress.items("eye rays: rows", d, n); }, &g_interrupted);
    progress.finish();
    out.seconds = seconds();
    return out;
}

int run_two_pass_render(const CommonOptions& o, const Scene& scene, const PatchMesh& mesh, const std::string& picture,
                        const RenderOptions& render, const TwoPassOptions& t) {
    const TwoPassPicture pic = render_two_pass(o, scene, mesh, render, t);
    write_eye_picture(pic.image, mesh, pic.shown, render.exposure, picture);
    if (!o.quiet) {
        std::cerr << "two-pass: " << mesh.size() << " patches, " << pic.shots << " shots";
        if (pic.emitted > 0)
            std::cerr << ", " << pic.stored << " caustic photons stored of " << pic.emitted << " emitted ("
                      << 100.0 * pic.specular_first << "% of the emitters' met a mirror or glass first)";
        std::cerr << "; light pass " << pic.light_seconds << " s, eye pass " << pic.seconds - pic.light_seconds
                  << " s\n";
    }
    if (!pic.image.complete()) {
        std::cerr << "bounce: interrupted: " << picture << " holds the " << pic.image.rows_done << " of "
                  << pic.image.height << " rows done (the rest black)\n";
        return interrupted_exit_code() ? interrupted_exit_code() : 130;
    }
    if (!o.quiet) std::cout << "wrote " << picture << "\n";
    return 0;
}

}  // namespace bounce::app
