// Ray throughput of the ground truth next to bare rtcIntersect1 / rtcOccluded1 on the same rays,
// the same scene and the same thread count, in one run. Not a ctest test: run
//   build/tests/reference/reference_benchmark [size] [samples per pixel] [threads]
#include "reference/reference.h"

#include "test_scenes.h"

#include <cstdio>
#include <cstdlib>

using namespace rtlab;
using namespace rtlab::reference;

int main(int argc, char** argv)
{
    const int size = argc > 1 ? std::atoi(argv[1]) : 128;
    const int spp = argc > 2 ? std::atoi(argv[2]) : 64;
    const int threads = argc > 3 ? std::atoi(argv[3]) : 0;

    // The test room plus 40 spheres of 1280 triangles each on the floor and the block.
    scene::RenderScene room = test::makeRoomScene();
    const auto grey = test::addMaterial(room, glm::vec3(0.6f));
    for (int i = 0; i < 40; ++i) {
        const float x = -1.7f + 0.42f * float(i % 9), z = -1.7f + 0.85f * float(i / 9);
        test::addIcosphere(room, glm::vec3(x, 0.18f, z), 0.18f, 3, false, grey);
    }
    const scene::GBuffer g = test::makeRoomGBuffer(room, size, size);

    std::printf("scene: %zu triangles, G-buffer %dx%d, %d samples per pixel\n",
                room.triangleCount(), size, size, spp);
    std::printf("%-12s %8s %14s %16s %16s\n", "quantity", "threads", "reference", "rtcIntersect1",
                "rtcOccluded1");
    for (Quantity q : {Quantity::Ao, Quantity::Obscurance, Quantity::Bent, Quantity::Full}) {
        ReferenceSettings s;
        s.quantity = q;
        s.radius = 1.0;
        s.threadCount = threads;
        const RayThroughput t =
            measureRayThroughput(room, g, s, q == Quantity::Full ? spp / 4 : spp);
        std::printf(
            "%-12s %8d %9.2f Mr/s %11.2f Mr/s %11.2f Mr/s   (%llu reference rays, %llu raw)\n",
            getQuantityName(q), t.threads, t.referenceMraysPerSecond, t.rawIntersectMraysPerSecond,
            t.rawOccludedMraysPerSecond, (unsigned long long)t.referenceRays,
            (unsigned long long)t.rawRays);
    }
    return 0;
}
