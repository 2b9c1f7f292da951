// SPDX-License-Identifier: MIT
// Accuracy against time of every form-factor method on the cases with known answers
// (shared/VALIDATION.md) and on unit parallel squares from c = 2 down to c = 0.001.
// Writes CSV: case,method,setting,value,exact,relative_error,seconds.
// Run through examples/form_factor_accuracy/run.sh, which also draws the chart.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <iostream>
#include <string>

#include "mesh/meshing/patch_mesh.h"
#include "mesh/readers/validation_scenes.h"
#include "solver/form_factors/form_factor_estimator.h"
#include "solver/form_factors/reference_form_factors.h"
#include "solver/form_factors/surface_form_factor.h"
#include "solver/visibility/visibility.h"

using namespace bounce;

namespace {

struct Case {
    std::string name;
    Scene scene;
    double exact;
    double size;   // the surfaces' size, to cut them into m x m patches
    int max_cuts;  // finest cutting worth running (the 96-gon disks make many triangles)
};

struct Setting {
    std::string method, label;
    FormFactorOptions options;
    int cuts;  // patches per side of each surface
};

}  // namespace

int main(int argc, char** argv) {
    const std::string out = argc > 1 ? argv[1] : "form_factor_accuracy.csv";
    std::vector<Case> cases;
    auto par = [&](double a, double b, double c) {
        char name[96];
        std::snprintf(name, sizeof name, "parallel %gx%g c=%g", a, b, c);
        cases.push_back({name, parallel_pair(a, b, c), parallel_rectangles(a, b, c), std::max(a, b), 16});
    };
    for (double c : {2.0, 1.0, 0.5, 0.2, 0.1, 0.05, 0.02, 0.01, 0.005, 0.002, 0.001}) par(1, 1, c);
    par(2, 1, 1);
    for (auto [h, w, l] : {std::tuple{1.0, 1.0, 1.0}, {2.0, 1.0, 1.0}, {1.0, 2.0, 1.0}, {1.0, 1.0, 0.5}}) {
        char name[96];
        std::snprintf(name, sizeof name, "perpendicular h=%g w=%g l=%g", h, w, l);
        cases.push_back(
            {name, perpendicular_pair(h, w, l), perpendicular_rectangles(h, w, l), std::max({h, w, l}), 16});
    }
    for (auto [r1, r2, h] : {std::tuple{1.0, 1.0, 1.0}, {0.5, 1.0, 1.0}, {1.0, 2.0, 0.5}}) {
        char name[96];
        std::snprintf(name, sizeof name, "disks r1=%g r2=%g h=%g", r1, r2, h);
        cases.push_back({name, coaxial_disks_scene(r1, r2, h), coaxial_disks(r1, r2, h), 2 * std::max(r1, r2), 4});
    }

    std::vector<Setting> settings;
    for (double tol : {1e-3, 1e-6, 1e-9}) {
        FormFactorOptions o;
        o.unoccluded_tolerance = tol;
        char label[32];
        std::snprintf(label, sizeof label, "tol=%g", tol);
        settings.push_back({"raycast", label, o, 1});
    }
    settings.push_back({"analytic", "tol=1e-06", FormFactorOptions{}, 1});
    settings.push_back({"exact", "tol=1e-08", FormFactorOptions{}, 1});
    for (int m : {1, 4, 16}) {
        FormFactorOptions o;
        o.receiver_samples = 1;
        settings.push_back({"raycast-point", "m=" + std::to_string(m), o, m});
    }
    for (int res : {64, 256})
        for (int m : {1, 4, 16}) {
            FormFactorOptions o;
            o.hemicube_resolution = res;
            settings.push_back({"hemicube", "res=" + std::to_string(res) + " m=" + std::to_string(m), o, m});
        }

    std::ofstream csv(out + ".tmp");
    csv << "case,method,setting,value,exact,relative_error,seconds\n";
    for (const auto& c : cases) {
        for (const auto& s : settings) {
            if (s.cuts > c.max_cuts) continue;
            MeshingOptions mo;
            mo.max_edge = c.size / s.cuts * (1 + 1e-9);
            mo.subdivide = s.cuts > 1;
            const PatchMesh mesh(c.scene, mo);
            const auto vis = make_cgal_visibility(mesh.patches());
            const std::string method = s.method == "raycast-point" ? "raycast" : s.method;
            const auto ff = make_form_factor_estimator(method, mesh.patches(), vis.get(), s.options);
            // Median of three timings: the machine is shared and noisy.
            std::vector<double> times;
            double value = 0;
            for (int rep = 0; rep < 3 && (times.empty() || times.back() < 2.0); ++rep) {
                const auto t0 = std::chrono::steady_clock::now();
                value = surface_form_factor(mesh.patches(), *ff, 0, 1);
                times.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
            }
            std::sort(times.begin(), times.end());
            const double median = times[times.size() / 2];
            csv << '"' << c.name << "\"," << s.method << ',' << s.label << ',' << value << ',' << c.exact << ','
                << std::abs(value - c.exact) / c.exact << ',' << median << '\n';
        }
        std::cerr << c.name << " done\n";
    }
    csv.close();
    std::rename((out + ".tmp").c_str(), out.c_str());
}
