// Fuzz target: scene files (scene::parseSceneFile), meshes and SDF models named in them included.

#include "fuzz_support.h"
#include "scene/scene_file.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    const std::string text(reinterpret_cast<const char*>(data), size);
    return rtlab::fuzz::runExpectingOnlyRtlabErrors([&] { rtlab::scene::parseSceneFile(text, "fuzz_scene.yaml"); });
}
