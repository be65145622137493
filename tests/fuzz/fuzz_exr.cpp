// Fuzz target: the EXR reads of cached references (experiment::readExrRgb / readExrScalar).

#include "experiment/image_files.h"
#include "core/image_file_size.h"
#include "fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    using namespace rtlab;
    // 2^18 values (the seeds hold at most 112): a header that passes the check still makes
    // the decoder allocate for it, which costs seconds per input under the sanitizers at 2^26.
    setImageFileValueLimit(1 << 18);
    const auto path = fuzz::getScratchDirectory() / "fuzz.exr";
    fuzz::writeFile(path, std::string(reinterpret_cast<const char*>(data), size));
    return fuzz::runExpectingOnlyRtlabErrors([&] {
        experiment::readExrRgb(path.string());
        experiment::readExrScalar(path.string());
    });
}
