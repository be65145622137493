// Fuzz target: the reference cache's EXR reads (reference::readReferenceExr): the input is
// written as both <quantity>.exr and <quantity>_stderr.exr of a folder and read back as an AO,
// a bent-cone and a radiance reference, each of which expects other channels and attributes.

#include "core/image_file_size.h"
#include "fuzz_support.h"
#include "reference/reference.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    using namespace rtlab;
    // 2^18 values (the seeds hold at most 112): a header that passes the check still makes
    // the decoder allocate for it, which costs seconds per input under the sanitizers at 2^26.
    setImageFileValueLimit(1 << 18);
    const std::string bytes(reinterpret_cast<const char*>(data), size);
    const auto dir = fuzz::getScratchDirectory() / "reference";
    std::filesystem::create_directories(dir);
    for (const reference::Quantity q : {reference::Quantity::Ao, reference::Quantity::Bent, reference::Quantity::Full}) {
        const std::string name = reference::getQuantityName(q);
        fuzz::writeFile(dir / (name + ".exr"), bytes);
        fuzz::writeFile(dir / (name + "_stderr.exr"), bytes);
        fuzz::runExpectingOnlyRtlabErrors([&] { reference::readReferenceExr(dir.string(), q); });
    }
    return 0;
}
