// SPDX-License-Identifier: MIT
// libFuzzer target for the scene readers: the input is written to a file and read as an OBJ
// (BOUNCE_FUZZ_OBJ) or a JSON scene (BOUNCE_FUZZ_JSON), then validated, checked and meshed
// with a small patch limit. Bad input must end in InputError, never a crash, hang or UB.
#include <unistd.h>

#include <cstdint>
#include <fstream>
#include <string>

#include "mesh/geometry/geometry_check.h"
#include "mesh/meshing/patch_mesh.h"
#include "mesh/readers/json_scene.h"
#include "mesh/readers/obj_reader.h"
#include "mesh/scene/input_error.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    static const std::string path = "/tmp/bounce-fuzz-" + std::to_string(::getpid()) + BOUNCE_FUZZ_EXT;
    {
        std::ofstream out(path, std::ios::binary | std::ios::trunc);
        out.write(reinterpret_cast<const char*>(data), std::streamsize(size));
    }
    try {
        bounce::Scene scene = BOUNCE_FUZZ_READ(path);
        scene.validate();
        bounce::check_geometry(scene, path);
        bounce::MeshingOptions o;
        o.max_patches = 20000;
        const bounce::PatchMesh mesh(scene, o);
        (void)mesh.total_area();
    } catch (const bounce::InputError&) {
    }
    return 0;
}
