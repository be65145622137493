// Fuzz target: glTF JSON and GLB (by the "glTF" magic), read and finished as a mesh.

#include "fuzz_support.h"
#include "scene/mesh_loader.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    using namespace rtlab;
    const std::string bytes(reinterpret_cast<const char*>(data), size);
    const bool binary = bytes.rfind("glTF", 0) == 0;
    const std::string path = (fuzz::getScratchDirectory() / (binary ? "fuzz.glb" : "fuzz.gltf")).string();
    return fuzz::runExpectingOnlyRtlabErrors([&] {
        const auto raw = scene::detail::readGltf(path, bytes, binary);
        scene::detail::finishMesh(path, raw);
    });
}
