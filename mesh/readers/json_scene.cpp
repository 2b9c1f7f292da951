// SPDX-License-Identifier: MIT
#include "mesh/readers/json_scene.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/Mesh/PolyMesh_ArrayKernelT.hh>
#include <nlohmann/json.hpp>

#include "mesh/readers/obj_reader.h"
#include "mesh/readers/text_file.h"
#include "mesh/scene/input_error.h"
#include "mesh/scene/sphere.h"
#include "mesh/scene/transform.h"

namespace bounce {
namespace {

using json = nlohmann::json;
using V = glm::dvec3;

struct Context {
    std::string where;  // "scene.json: objects[2]"
    [[noreturn]] void fail(const std::string& why) const { throw InputError(where + ": " + why); }
    void only_keys(const json& j, std::initializer_list<const char*> keys) const {
        if (!j.is_object()) fail("expected an object");
        std::set<std::string> ok(keys.begin(), keys.end());
        for (auto it = j.begin(); it != j.end(); ++it)
            if (!ok.count(it.key())) fail("unknown key '" + it.key() + "'");
    }
    double number(const json& j, const std::string& what) const {
        if (!j.is_number()) fail(what + " must be a number");
        const double v = j.get<double>();
        if (!std::isfinite(v)) fail(what + " is not finite");
        return v;
    }
    V vec3(const json& j, const std::string& what) const {
        if (!j.is_array() || j.size() != 3) fail(what + " must be an array of 3 numbers");
        return {number(j[0], what), number(j[1], what), number(j[2], what)};
    }
    Rgb rgb(const json& j, const std::string& what) const {
        if (j.is_number()) return Rgb::gray(number(j, what));
        const V v = vec3(j, what);
        return {v.x, v.y, v.z};
    }
};

Transform parse_transform(const json& j, const Context& cx) {
    cx.only_keys(j, {"translate", "rotate", "scale", "matrix"});
    Transform t;
    if (j.contains("matrix")) {
        if (j.size() != 1) cx.fail("transform: 'matrix' cannot be combined with translate/rotate/scale");
        const json& m = j["matrix"];
        if (!m.is_array() || m.size() != 16) cx.fail("transform.matrix must have 16 numbers (row-major 4x4)");
        glm::dmat4 mat(1.0);
        for (int r = 0; r < 4; ++r)
            for (int c = 0; c < 4; ++c) mat[c][r] = cx.number(m[4 * r + c], "transform.matrix");
        if (mat[0][3] != 0 || mat[1][3] != 0 || mat[2][3] != 0 || mat[3][3] != 1)
            cx.fail("transform.matrix must be affine (last row 0 0 0 1)");
        t = Transform(mat);
    } else {
        if (j.contains("scale")) {
            const json& s = j["scale"];
            t = Transform::scale(s.is_number() ? V(cx.number(s, "scale")) : cx.vec3(s, "transform.scale"));
        }
        if (j.contains("rotate")) {
            const json& r = j["rotate"];
            cx.only_keys(r, {"axis", "degrees"});
            if (!r.contains("axis") || !r.contains("degrees")) cx.fail("rotate needs 'axis' and 'degrees'");
            const V axis = cx.vec3(r["axis"], "rotate.axis");
            if (glm::length(axis) == 0.0) cx.fail("rotate.axis is zero");
            t = Transform::rotate(cx.number(r["degrees"], "rotate.degrees"), axis) * t;
        }
        if (j.contains("translate")) t = Transform::translate(cx.vec3(j["translate"], "transform.translate")) * t;
    }
    if (!t.is_invertible()) cx.fail("transform is singular (flattens the object)");
    return t;
}

std::vector<std::vector<V>> unit_quad() { return {{{-0.5, -0.5, 0}, {0.5, -0.5, 0}, {0.5, 0.5, 0}, {-0.5, 0.5, 0}}}; }

std::vector<std::vector<V>> unit_box() {
    // Counter-clockwise seen from outside.
    const double h = 0.5;
    return {
        {{-h, -h, h}, {h, -h, h}, {h, h, h}, {-h, h, h}},      // +z
        {{h, -h, -h}, {-h, -h, -h}, {-h, h, -h}, {h, h, -h}},  // -z
        {{h, -h, h}, {h, -h, -h}, {h, h, -h}, {h, h, h}},      // +x
        {{-h, -h, -h}, {-h, -h, h}, {-h, h, h}, {-h, h, -h}},  // -x
        {{-h, h, h}, {h, h, h}, {h, h, -h}, {-h, h, -h}},      // +y
        {{-h, -h, -h}, {h, -h, -h}, {h, -h, h}, {-h, -h, h}},  // -y
    };
}

using OmMesh = OpenMesh::PolyMesh_ArrayKernelT<>;

std::vector<std::vector<V>> read_polygons_openmesh(const std::filesystem::path& file, const Context& cx) {
    read_text_file(file, "mesh file");  // existence, directory and readability checks with a clear message
    OmMesh mesh;
    OpenMesh::IO::Options opt;
    if (!OpenMesh::IO::read_mesh(mesh, file.string(), opt)) cx.fail("cannot read mesh file " + file.string());
    std::vector<std::vector<V>> polys;
    for (auto f : mesh.faces()) {
        std::vector<V> poly;
        for (auto v : mesh.fv_range(f)) {
            const auto p = mesh.point(v);
            poly.emplace_back(p[0], p[1], p[2]);
        }
        polys.push_back(std::move(poly));
    }
    return polys;
}

}  // namespace

Scene read_mesh_scene(const std::filesystem::path& path) {
    const Context cx{path.string()};
    Scene scene;
    scene.name = path.stem().string();
    // .ply and .off carry no materials: every face white 0.5, said once (as for an OBJ
    // without a material library).
    scene.materials.push_back({"default white 0.5", Rgb::gray(0.5), Rgb()});
    int face = 0;
    for (auto& poly : read_polygons_openmesh(path, cx))
        scene.surfaces.push_back({std::move(poly), 0, "", {path.string() + ": face " + std::to_string(++face), 0}});
    scene.warnings.push_back(path.string() + ": " + std::to_string(face) +
                             " face(s) have no material (.ply and .off carry none); using white 0.5");
    return scene;
}

namespace {

/// The JSON document at `path`; a syntax error becomes an InputError naming the file.
json parse_json_file(const std::filesystem::path& path) {
    const std::string text = read_text_file(path, "JSON scene");
    try {
        return json::parse(text);
    } catch (const json::exception& e) {
        // parse_error, and out_of_range for numbers too large for a double (found by fuzzing).
        std::string msg = e.what();
        if (auto p = msg.find("] "); p != std::string::npos) msg = msg.substr(p + 2);
        throw InputError(path.string() + ": " + msg);
    }
}

/// One entry of "materials": diffuse (reflectance, emission), mirror (reflectance) or glass
/// (ior, transmittance), checked against its kind's keys and ranges.
Material parse_material(const std::string& name, const json& j, const Context& cx) {
    Material m{name, Rgb::gray(0.5), Rgb()};
    const std::string kind =
        j.is_object() && j.contains("kind") && j["kind"].is_string() ? j["kind"].get<std::string>() : "diffuse";
    if (kind == "diffuse") {
        cx.only_keys(j, {"kind", "reflectance", "emission"});
        if (j.contains("reflectance")) m.reflectance = cx.rgb(j["reflectance"], "reflectance");
        if (j.contains("emission")) m.emission = cx.rgb(j["emission"], "emission");
    } else if (kind == "mirror") {
        // An ideal mirror: reflectance per channel, 1 unless given.
        cx.only_keys(j, {"kind", "reflectance"});
        m.kind = MaterialKind::mirror;
        m.reflectance = Rgb();
        m.specular = j.contains("reflectance") ? cx.rgb(j["reflectance"], "reflectance") : Rgb::gray(1);
        if (m.specular.min() < 0 || m.specular.max() > 1)
            cx.fail("mirror reflectance out of range, got " + m.specular.to_string() +
                    " (expected 0 to 1 per channel)");
    } else if (kind == "glass") {
        // A dielectric: index of refraction (1.5 unless given) and transmittance colour (1).
        cx.only_keys(j, {"kind", "ior", "transmittance"});
        m.kind = MaterialKind::glass;
        m.reflectance = Rgb();
        if (j.contains("ior")) m.ior = cx.number(j["ior"], "ior");
        if (j.contains("transmittance")) m.specular = cx.rgb(j["transmittance"], "transmittance");
        if (!(m.ior >= 1))
            cx.fail("index of refraction 'ior' out of range, got " + number_text(m.ior) + " (expected >= 1)");
        if (m.specular.min() < 0 || m.specular.max() > 1)
            cx.fail("glass transmittance out of range, got " + m.specular.to_string() +
                    " (expected 0 to 1 per channel)");
    } else {
        cx.fail("unknown kind '" + kind + "' (expected diffuse, mirror or glass)");
    }
    if (m.reflectance.min() < 0 || m.reflectance.max() > 1)
        cx.fail("reflectance out of range, got " + m.reflectance.to_string() + " (expected 0 to 1 per channel)");
    if (m.emission.min() < 0)
        cx.fail("emission out of range, got " + m.emission.to_string() + " (expected >= 0 per channel)");
    return m;
}

/// The document's "materials" appended to scene.materials; returns each name's index.
std::map<std::string, int> read_materials(const json& doc, const std::filesystem::path& path, const Context& top,
                                          Scene& scene) {
    std::map<std::string, int> byname;
    if (!doc.contains("materials")) return byname;
    if (!doc["materials"].is_object()) top.fail("'materials' must be an object of named materials");
    for (auto it = doc["materials"].begin(); it != doc["materials"].end(); ++it) {
        const Context cx{path.string() + ": material '" + it.key() + "'"};
        const Material m = parse_material(it.key(), it.value(), cx);
        byname[m.name] = int(scene.materials.size());
        scene.materials.push_back(m);
    }
    return byname;
}

/// The keys every entry of "objects" shares, checked.
struct ObjectHeader {
    std::string type;   // quad, box, sphere or mesh
    std::string name;   // its "name", or "<type> <index>"
    int material = -1;  // index into Scene::materials; -1: none given
    Transform transform;
    bool flip = false;  // "flip", xor "inward" for boxes
};

ObjectHeader parse_object_header(const json& o, std::size_t k, const std::map<std::string, int>& byname,
                                 const Context& cx) {
    ObjectHeader h;
    cx.only_keys(o, {"type", "file", "material", "transform", "flip", "inward", "name"});
    if (!o.contains("type") || !o["type"].is_string()) cx.fail("needs a 'type' (quad, box, sphere or mesh)");
    h.type = o["type"].get<std::string>();
    h.name =
        o.contains("name") && o["name"].is_string() ? o["name"].get<std::string>() : h.type + " " + std::to_string(k);
    if (o.contains("material")) {
        if (!o["material"].is_string()) cx.fail("'material' must name an entry of 'materials'");
        auto it = byname.find(o["material"].get<std::string>());
        if (it == byname.end()) cx.fail("material '" + o["material"].get<std::string>() + "' is not defined");
        h.material = it->second;
    }
    h.transform = o.contains("transform") ? parse_transform(o["transform"], cx) : Transform();
    if (o.contains("flip")) {
        if (!o["flip"].is_boolean()) cx.fail("'flip' must be true or false");
        h.flip = o["flip"];
    }
    if (o.contains("inward")) {
        if (h.type != "box" || !o["inward"].is_boolean()) cx.fail("'inward' is a true/false option of boxes");
        h.flip = h.flip != o["inward"].get<bool>();
    }
    return h;
}

/// The faces of a "mesh" object's file (.obj, .ply or .off, beside the scene file), untransformed.
/// An OBJ's materials and warnings are appended to the scene's.
std::vector<Surface> mesh_object_surfaces(const json& o, const ObjectHeader& h, const std::filesystem::path& path,
                                          const Context& cx, Scene& scene) {
    std::vector<Surface> surfaces;
    if (!o.contains("file") || !o["file"].is_string()) cx.fail("type mesh needs a 'file'");
    const std::filesystem::path file = path.parent_path() / o["file"].get<std::string>();
    const std::string ext = file.extension().string();
    // Tied to its object here: the readers' own "cannot open" names only the file.
    std::error_code ec;
    if (!std::filesystem::is_regular_file(file, ec))
        cx.fail("mesh file " + file.string() +
                (std::filesystem::exists(file, ec) ? " is not a regular file" : " not found"));
    if (ext == ".obj" || ext == ".OBJ") {
        // The object's material replaces the file's: its faces do not lack one.
        Scene sub = read_obj(file, h.material < 0);
        const int base = int(scene.materials.size());
        for (auto& m : sub.materials) scene.materials.push_back(m);
        for (auto& w : sub.warnings) scene.warnings.push_back(w);
        for (auto& s : sub.specular_surfaces) sub.surfaces.push_back(std::move(s));
        for (auto& s : sub.surfaces) {
            s.material = h.material >= 0 ? h.material : base + s.material;
            // Named by the JSON object (and the OBJ's own object, when it names one)
            // rather than the OBJ reader's "default".
            s.object = s.object == "default" ? h.name : h.name + "/" + s.object;
            surfaces.push_back(std::move(s));
        }
    } else if (ext == ".ply" || ext == ".off" || ext == ".PLY" || ext == ".OFF") {
        for (auto& poly : read_polygons_openmesh(file, cx))
            surfaces.push_back({poly, h.material, h.name, {file.string(), 0}});
    } else {
        cx.fail("mesh file " + file.string() + " is not .obj, .ply or .off");
    }
    return surfaces;
}

/// The surfaces of one object before its transform. A mirror or glass sphere stays analytic:
/// it goes into scene.spheres, placed, and no surfaces come back.
std::vector<Surface> object_surfaces(const json& o, const ObjectHeader& h, const std::filesystem::path& path,
                                     const Context& cx, Scene& scene) {
    std::vector<Surface> surfaces;
    const std::string& type = h.type;
    if (type == "sphere") {
        if (o.contains("file")) cx.fail("'file' belongs to type mesh");
        if (o.contains("flip")) cx.fail("'flip' does not apply to spheres (their front is the outside)");
        const std::string where = o.contains("name") ? cx.where + " (sphere)" : cx.where;
        if (h.material >= 0 && scene.materials[std::size_t(h.material)].is_specular()) {
            // Mirror and glass spheres stay analytic: the path tracer and the eye pass
            // intersect them exactly.
            scene.spheres.push_back({h.transform, h.material, h.name, {where, 0}});
            return surfaces;
        }
        // A diffuse sphere is meshed like any surface: its inscribed 32 x 16 polyhedron.
        for (auto& poly : tessellate_sphere(Transform(), 32, 16))
            surfaces.push_back({poly, h.material, h.name, {where, 0}});
    } else if (type == "quad" || type == "box") {
        if (o.contains("file")) cx.fail("'file' belongs to type mesh");
        // "objects[2] (box 2)" unnamed, "objects[3] (quad) (east wall)" named: the type once.
        const std::string where = o.contains("name") ? cx.where + " (" + type + ")" : cx.where;
        for (auto& poly : (type == "quad" ? unit_quad() : unit_box()))
            surfaces.push_back({poly, h.material, h.name, {where, 0}});
    } else if (type == "mesh") {
        surfaces = mesh_object_surfaces(o, h, path, cx, scene);
    } else {
        cx.fail("unknown type '" + type + "' (expected quad, box, sphere or mesh)");
    }
    return surfaces;
}

/// Places an object's surfaces into the scene: the default white 0.5 where no material is
/// given (added once, at `default_material`, with a warning), the transform, the winding.
void place_surfaces(std::vector<Surface>& surfaces, const ObjectHeader& h, const Context& cx, int& default_material,
                    Scene& scene) {
    const Transform& t = h.transform;
    for (auto& s : surfaces) {
        if (s.material < 0) {
            if (default_material < 0) {
                default_material = int(scene.materials.size());
                scene.materials.push_back({"default white 0.5", Rgb::gray(0.5), Rgb()});
                scene.warnings.push_back(cx.where + ": no material; using white 0.5");
            }
            s.material = default_material;
        }
        for (auto& v : s.vertices) v = t.point(v);
        // A mirroring transform reverses the winding; reverse it back so the front stays
        // the side the inverse-transpose normal points to.
        if (t.flips_orientation() != h.flip) std::reverse(s.vertices.begin(), s.vertices.end());
        (scene.materials[std::size_t(s.material)].is_specular() ? scene.specular_surfaces : scene.surfaces)
            .push_back(std::move(s));
    }
}

}  // namespace

Scene read_json_scene(const std::filesystem::path& path) {
    const json doc = parse_json_file(path);
    Context top{path.string()};
    top.only_keys(doc, {"name", "materials", "objects"});
    Scene scene;
    scene.name =
        doc.contains("name") && doc["name"].is_string() ? doc["name"].get<std::string>() : path.stem().string();
    const std::map<std::string, int> byname = read_materials(doc, path, top, scene);
    if (!doc.contains("objects") || !doc["objects"].is_array()) top.fail("'objects' must be an array");
    int default_material = -1;
    const json& objects = doc["objects"];
    for (std::size_t k = 0; k < objects.size(); ++k) {
        const json& o = objects[k];
        const Context cx{path.string() + ": objects[" + std::to_string(k) + "]"};
        const ObjectHeader h = parse_object_header(o, k, byname, cx);
        std::vector<Surface> surfaces = object_surfaces(o, h, path, cx, scene);
        place_surfaces(surfaces, h, cx, default_material, scene);
    }
    return scene;
}

}  // namespace bounce
