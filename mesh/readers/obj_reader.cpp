// SPDX-License-Identifier: MIT
#include "mesh/readers/obj_reader.h"

#include <charconv>
#include <cmath>
#include <map>
#include <optional>

#include "mesh/readers/text_file.h"
#include "mesh/scene/input_error.h"

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
    if (w.size() != 2 && w.size() != 4) throw InputError(where + ": " + std::string(w[0]) + " needs 1 or 3 numbers");
    Rgb c;
    for (int k = 0; k < 3; ++k) {
        double v;
        if (!parse_double(w[w.size() == 2 ? 1 : 1 + k], v) || !std::isfinite(v))
            throw InputError(where + ": " + std::string(w[0]) + " has a bad number");
        c[k] = v;
    }
    return c;
}

/// The statements of one MTL material that choose its kind, read in any order and applied at
/// its end (finish_material).
struct MtlStatements {
    int illum = -1;  // -1: not given
    std::optional<Rgb> ks, tf;
    std::optional<double> ni;
    std::string where;  // "file.mtl:12" of its newmtl
};

/// The illumination models of the MTL specification that bounce can follow:
///   illum 0, 1, 2 (colour, ambient, highlight): diffuse, Kd (Ks, the highlight, is ignored);
///   illum 3 (reflection, ray trace on) and 5 (reflection with Fresnel, ray trace on): a
///     mirror of reflectance Ks at every angle. Illum 5's Fresnel would need a metal's complex
///     index, which MTL does not carry, so both take Ks as it is;
///   illum 6 (refraction, Fresnel off) and 7 (refraction, Fresnel on): glass of index Ni
///     (1.5 when not given, with a warning) and transmittance colour Tf (1 when not given).
///     bounce always applies the exact Fresnel equations for a dielectric, so 6 is read as 7;
///   illum 4, 8, 9, 10 (transparency or reflection without refraction, shadow tricks): not
///     modelled; diffuse from Kd, with a warning.
/// Kd is ignored for mirror and glass; Ke on them is an error (they do not emit).
void finish_material(Material& m, const MtlStatements& st, Scene& scene) {
    if (st.illum == 3 || st.illum == 5) {
        if (!st.ks)
            throw InputError(st.where + ": material '" + m.name + "' is a mirror (illum " + std::to_string(st.illum) +
                             ") but gives no Ks (its reflectance)");
        m.kind = MaterialKind::mirror;
        m.specular = *st.ks;
        m.reflectance = Rgb();
    } else if (st.illum == 6 || st.illum == 7) {
        m.kind = MaterialKind::glass;
        m.reflectance = Rgb();
        m.specular = st.tf.value_or(Rgb::gray(1.0));
        if (st.ni) {
            m.ior = *st.ni;
        } else {
            m.ior = 1.5;
            scene.warnings.push_back(st.where + ": material '" + m.name + "' is glass (illum " +
                                     std::to_string(st.illum) + ") but gives no Ni; using 1.5");
        }
    } else if (st.illum == 4 || st.illum >= 8) {
        scene.warnings.push_back(st.where + ": material '" + m.name + "': illum " + std::to_string(st.illum) +
                                 " is not modelled (mirror is illum 3 or 5, glass 6 or 7); diffuse from Kd");
    }
    if (!m.is_specular()) return;
    const std::string what = m.kind == MaterialKind::mirror ? "mirror reflectance Ks" : "glass transmittance Tf";
    if (m.specular.min() < 0.0 || m.specular.max() > 1.0)
        throw InputError(st.where + ": material '" + m.name + "': " + what + " out of range, got " +
                         m.specular.to_string() + " (expected 0 to 1 per channel)");
    if (!(m.ior >= 1.0))
        throw InputError(st.where + ": material '" + m.name + "': index of refraction Ni out of range, got " +
                         number_text(m.ior) + " (expected >= 1)");
    if (m.emission.max() > 0.0)
        throw InputError(st.where + ": material '" + m.name + "': a " + to_string(m.kind) + " does not emit, got Ke " +
                         m.emission.to_string());
}

void read_mtl(const std::filesystem::path& path, Scene& scene, std::map<std::string, int>& byname) {
    Lines in{read_text_file(path, "MTL file")};
    std::string_view line;
    int current = -1;
    MtlStatements statements;
    while (in.next(line)) {
        const auto w = split_words(line);
        if (w.empty()) continue;
        const std::string where = path.string() + ":" + std::to_string(in.number);
        if (w[0] == "newmtl") {
            if (w.size() < 2) throw InputError(where + ": newmtl without a name");
            if (current >= 0) finish_material(scene.materials[std::size_t(current)], statements, scene);
            const std::string name(w[1]);
            scene.materials.push_back({name, Rgb::gray(0.5), Rgb()});
            current = int(scene.materials.size()) - 1;
            byname[name] = current;
            statements = MtlStatements{};
            statements.where = where;
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
        } else if (w[0] == "Ks" || w[0] == "Tf") {
            if (current < 0) throw InputError(where + ": " + std::string(w[0]) + " before newmtl");
            // Tf may be written "Tf xyz ..." or as a spectral file: only RGB is read.
            if (w.size() >= 2 && (w[1] == "xyz" || w[1] == "spectral")) continue;
            (w[0] == "Ks" ? statements.ks : statements.tf) = parse_rgb(w, where);
        } else if (w[0] == "Ni" || w[0] == "illum") {
            if (current < 0) throw InputError(where + ": " + std::string(w[0]) + " before newmtl");
            double v = 0;
            if (w.size() != 2 || !parse_double(w[1], v) || !std::isfinite(v))
                throw InputError(where + ": " + std::string(w[0]) + " needs one number");
            if (w[0] == "Ni") {
                statements.ni = v;
            } else {
                if (v != std::floor(v) || v < 0 || v > 10)
                    throw InputError(where + ": illum out of range, got " + std::string(w[1]) +
                                     " (expected a whole number 0 to 10)");
                statements.illum = int(v);
            }
        }
        // Other statements (Ka, Ns, d, maps) do not enter the light transport bounce models.
    }
    if (current >= 0) finish_material(scene.materials[std::size_t(current)], statements, scene);
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
                if (!parse_double(w[1 + k], p[k]))
                    throw InputError(where + ": vertex has a bad number '" + std::string(w[1 + k]) + "'");
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
            const bool specular = s.material >= 0 && scene.materials[std::size_t(s.material)].is_specular();
            (specular ? scene.specular_surfaces : scene.surfaces).push_back(std::move(s));
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
