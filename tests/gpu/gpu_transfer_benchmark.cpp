// Host <-> device transfers through staging buffers: kept between transfers (the default) against
// one allocated per transfer (ContextOptions::keepStagingBuffers = false), in one run. On a
// discrete GPU every buffer transfer goes through staging; on a CPU device such as lavapipe only
// images do, unless forced, so buffers are forced through staging here on every device.
// Sizes: a 320x180 pixel gather's cone radiances (0.9 MB), one 32^3 cascade level's 16
// pre-combined directions (8 MiB), a 1280x720 RGBA32F image (14 MB, upload and read-back).
// The two contexts take turns round by round; each keeps its median.
//
//   gpu_transfer_benchmark [--quick] [--repeats n]
// --quick: small sizes, 3 rounds (the ctest that keeps this compiling and running).

#include "gpu/context.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

using namespace rtlab;

namespace {

double millisecondsOf(const auto& work)
{
    const auto start = std::chrono::steady_clock::now();
    work();
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
        .count();
}

double medianOf(std::vector<double> v)
{
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
}

struct Case {
    const char* name;
    std::size_t bytes;                   // buffer cases
    std::uint32_t width = 0, height = 0; // image cases (RGBA32F)
};

} // namespace

int main(int argc, char** argv)
{
    bool quick = false;
    int repeats = 15;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "--quick")
            quick = true;
        else if (a == "--repeats" && i + 1 < argc)
            repeats = std::max(1, std::atoi(argv[++i]));
        else {
            std::fprintf(stderr, "usage: gpu_transfer_benchmark [--quick] [--repeats n]\n");
            return 2;
        }
    }
    if (quick)
        repeats = 3;
    const std::vector<Case> cases =
        quick ? std::vector<Case>{{"buffer 64 KB", 64 << 10}, {"image 64x64", 0, 64, 64}}
              : std::vector<Case>{{"gather cone radiances, 320x180 / 16 pixels", 3600 * 16 * 16},
                                  {"one 32^3 level, 16 directions", 32768 * 16 * 16},
                                  {"image 1280x720 RGBA32F", 0, 1280, 720}};

    gpu::ContextOptions keptOptions;
    keptOptions.forceStagingUploads = true;
    gpu::ContextOptions freshOptions = keptOptions;
    freshOptions.keepStagingBuffers = false;
    gpu::Context kept(keptOptions);
    gpu::Context fresh(freshOptions);
    std::printf(
        "device: %s\ntime: wall, upload then download, median of %d (contexts alternating)\n\n",
        kept.getDeviceInfo().name.c_str(), repeats);
    std::printf("%-44s %12s %12s %8s\n", "transfer", "kept ms", "per-call ms", "ratio");

    for (const Case& c : cases) {
        const std::size_t bytes = c.width ? std::size_t(c.width) * c.height * 16 : c.bytes;
        std::vector<unsigned char> data(bytes), back(bytes);
        for (std::size_t i = 0; i < bytes; ++i)
            data[i] = static_cast<unsigned char>(i * 131u + 7u);
        std::vector<double> keptMs, freshMs;
        if (c.width) {
            gpu::ImageDesc desc;
            desc.width = c.width;
            desc.height = c.height;
            desc.name = "transfer_benchmark.image";
            gpu::Image a = kept.createImage(desc);
            gpu::Image b = fresh.createImage(desc);
            const auto trip = [&](gpu::Image& image) {
                image.upload(data.data(), bytes);
                image.download(back.data(), bytes);
            };
            trip(a), trip(b); // untimed: first use
            for (int r = 0; r < repeats; ++r) {
                keptMs.push_back(millisecondsOf([&] { trip(a); }));
                freshMs.push_back(millisecondsOf([&] { trip(b); }));
            }
        } else {
            gpu::Buffer a = kept.createBuffer({bytes, "transfer_benchmark.kept"});
            gpu::Buffer b = fresh.createBuffer({bytes, "transfer_benchmark.fresh"});
            const auto trip = [&](gpu::Buffer& buffer) {
                buffer.upload(data.data(), bytes);
                buffer.download(back.data(), bytes);
            };
            trip(a), trip(b);
            for (int r = 0; r < repeats; ++r) {
                keptMs.push_back(millisecondsOf([&] { trip(a); }));
                freshMs.push_back(millisecondsOf([&] { trip(b); }));
            }
        }
        if (std::memcmp(data.data(), back.data(), bytes) != 0) {
            std::fprintf(stderr, "%s: the data read back differs from the data sent\n", c.name);
            return 1;
        }
        const double k = medianOf(keptMs), f = medianOf(freshMs);
        std::printf("%-44s %12.3f %12.3f %8.2f\n", c.name, k, f, k / f);
    }
    return 0;
}
