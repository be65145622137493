// Fuzz target: OBJ with its MTL. The input is the OBJ text, then optionally a line "#MTL" and the
// MTL text, which is written beside it as fuzz.mtl (the OBJ is given "mtllib fuzz.mtl" first).
// The mesh is read and finished (degenerate triangles, vertex merging, normals, materials).

#include "fuzz_support.h"
#include "scene/mesh_loader.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    using namespace rtlab;
    const std::string input(reinterpret_cast<const char*>(data), size);
    const std::size_t split = input.find("\n#MTL\n");
    const std::string obj = "mtllib fuzz.mtl\n" + input.substr(0, split);
    const std::string mtl = split == std::string::npos ? std::string() : input.substr(split + 6);
    const auto& dir = fuzz::getScratchDirectory();
    fuzz::writeFile(dir / "fuzz.mtl", mtl);
    const std::string path = (dir / "fuzz.obj").string();
    return fuzz::runExpectingOnlyRtlabErrors([&] {
        for (bool optional : {false, true}) {
            scene::MeshLoadOptions options;
            options.materialsOptional = optional;
            const auto raw = scene::detail::readObj(path, obj, options);
            scene::detail::finishMesh(path, raw);
        }
    });
}
