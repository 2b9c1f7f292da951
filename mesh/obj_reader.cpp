// SPDX-License-Identifier: MIT
#include "mesh/obj_reader.h"

#include <charconv>
#include <cmath>
#include <map>

#include "mesh/input_error.h"
#include "mesh/text_file.h"

namespace bounce {
namespace {

struct Lines {
    std::string text;
    std::size_t pos = 0;
    int number = 0;
    bool next(std::string_view& line) {
        if (pos >= text.size()) return false;
        std::size_t e = text.find('\n', pos);
        if (e == std::string::npos) e = text.size();
        line = std::string_view(text).substr(pos, e - pos);
        pos = e + 1;
        ++number;
        return true;
    }
};

Rgb parse_rgb(const std::vector<std::string_view>& w, const std::string& where) {
    if (w.size() != 2 && w.size() != 4)
        throw InputError(where + ": " + std::string(w[0]) + " needs 1 or 3 numbers");
    Rgb c;
    for (int k = 0; k < 3; ++k) {
        double v;
        if (!parse_double(w[w.size() == 2 ? 1 : 1 + k], v) || !std::isfinite(v))
            throw InputError(where + ": " + std::string(w[0]) + " has a bad number");
        c[k] = v;
    }
    return c;
}

void read_mtl(const std::filesystem::path& path, Scene& scene, std::map<std::string, int>& byname) {
    Lines in{read_text_file(path, "MTL file")};
    std::string_view line;
    int current = -1;
    while (in.next(line)) {
        const auto w = split_words(line);
        if (w.empty()) continue;
        const std::string where = path.string() + ":" + std::to_string(in.number);
        if (w[0] == "newmtl") {
            if (w.size() < 2) throw InputError(where + ": newmtl without a name");
            const std::string name(w[1]);
            scene.materials.push_back({name, Rgb::gray(0.5), Rgb()});
            current = int(scene.materials.size()) - 1;
            byname[name] = current;
        } else if (w[0] == "Kd" || w[0] == "Ke") {
            if (current < 0) throw InputError(where + ": " + std::string(w[0]) + " before newmtl");
            const Rgb c = parse_rgb(w, where);
            if (w[0] == "Kd") {
                if (c.min() < 0.0 || c.max() > 1.0)
                    throw InputError(where + ": reflectance Kd out of range, got " + c.to_string() +
                                     " (expected 0 to 1 per channel)");
                scene.materials[current].reflectance = c;
            } else {
                if (c.min() < 0.0)
                    throw InputError(where + ": emission Ke out of range, got " + c.to_string() +
                                     " (expected >= 0 per channel)");
                scene.materials[current].emission = c;
            }
        }
        // Other statements (Ka, Ks, Ns, Ni, d, illum, maps) do not enter diffuse radiosity.
    }
}

}  // namespace

Scene read_obj(const std::filesystem::path& path, bool own_materials) {
    Lines in{read_text_file(path, "OBJ file")};
    Scene scene;
    scene.name = path.stem().string();
    std::map<std::string, int> byname;
    std::vector<glm::dvec3> verts;
    int current = -1;  // material of the faces that follow; -1: none
    int default_material = -1;
    int faces_without_material = 0, faces_unknown_material = 0;
    std::string object = "default";
    std::string_view line;
    while (in.next(line)) {
        const auto w = split_words(line);
        if (w.empty()) continue;
        const std::string where = path.string() + ":" + std::to_string(in.number);
        const std::string_view key = w[0];
        if (key == "v") {
            if (w.size() < 4) throw InputError(where + ": vertex needs 3 coordinates");
            glm::dvec3 p;
            for (int k = 0; k < 3; ++k) {
                if (!parse_double(w[1 + k], p[k])) throw InputError(where + ": vertex has a bad number '" + std::string(w[1 + k]) + "'");
                if (!std::isfinite(p[k])) throw InputError(where + ": vertex has a NaN or infinite coordinate");
            }
            verts.push_back(p);
        } else if (key == "f") {
            if (w.size() < 4) throw InputError(where + ": face needs at least 3 vertices");
            Surface s;
            s.object = object;
            s.where = {path.string(), in.number};
            for (std::size_t k = 1; k < w.size(); ++k) {
                const std::string_view tok = w[k].substr(0, w[k].find('/'));
                long idx = 0;
                auto [ptr, ec] = std::from_chars(tok.data(), tok.data() + tok.size(), idx);
                if (ec != std::errc() || ptr != tok.data() + tok.size() || idx == 0)
                    throw InputError(where + ": bad vertex index '" + std::string(w[k]) + "'");
                const long n = long(verts.size());
                const long i = idx > 0 ? idx - 1 : n + idx;  // negative: relative to the last vertex
                if (i < 0 || i >= n)
                    throw InputError(where + ": vertex index " + std::to_string(idx) + " out of range (" +
                                     std::to_string(n) + " vertices so far)");
                s.vertices.push_back(verts[i]);
            }
            if (!own_materials) {
                s.material = -1;
            } else if (current < 0) {
                if (default_material < 0) {
                    scene.materials.push_back({"default white 0.5", Rgb::gray(0.5), Rgb()});
                    default_material = int(scene.materials.size()) - 1;
                }
                s.material = default_material;
                (current == -1 ? faces_without_material : faces_unknown_material)++;
            } else {
                s.material = current;
            }
            scene.surfaces.push_back(std::move(s));
        } else if (key == "o" || key == "g") {
            object = w.size() > 1 ? std::string(w[1]) : "default";
        } else if (key == "usemtl" && own_materials) {
            const std::string name = w.size() > 1 ? std::string(w[1]) : "";
            auto it = byname.find(name);
            if (it != byname.end()) {
                current = it->second;
            } else {
                current = -2;
                scene.warnings.push_back(where + ": material '" + name + "' is not defined; using white 0.5");
            }
        } else if (key == "mtllib" && own_materials) {
            for (std::size_t k = 1; k < w.size(); ++k) {
                const auto lib = path.parent_path() / std::string(w[k]);
                std::error_code ec;
                if (!std::filesystem::exists(lib, ec)) {
                    scene.warnings.push_back(where + ": material library " + lib.string() + " not found");
                    continue;
                }
                read_mtl(lib, scene, byname);
            }
        }
        // vt, vn, s, l, p and others carry nothing a diffuse radiosity solution uses.
    }
    if (faces_without_material > 0)
        scene.warnings.push_back(path.string() + ": " + std::to_string(faces_without_material) +
                                 " face(s) have no material; using white 0.5");
    if (faces_unknown_material > 0)
        scene.warnings.push_back(path.string() + ": " + std::to_string(faces_unknown_material) +
                                 " face(s) use an undefined material; using white 0.5");
    return scene;
}

}  // namespace bounce
