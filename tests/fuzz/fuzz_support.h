#pragma once
// What the fuzz targets share: a bad input must end in rtlab::Error (a clear error naming the
// file and line), never in another exception, a crash, a hang or a sanitizer report. An escaping
// exception of another type reaches std::terminate, which libFuzzer reports as a crash.

#include "core/error.h"

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>

namespace rtlab::fuzz {

//! Calls f; rtlab::Error (the project's clear error for bad input) is an expected outcome.
template <class F> int runExpectingOnlyRtlabErrors(F&& f)
{
    try {
        f();
    } catch (const Error&) {
    }
    return 0;
}

//! A folder of this process for inputs that must be files (MTL beside an OBJ, EXR images).
inline const std::filesystem::path& getScratchDirectory()
{
    static const std::filesystem::path dir = [] {
        auto d = std::filesystem::temp_directory_path() / ("rtlab_fuzz_" + std::to_string(::getpid()));
        std::filesystem::create_directories(d);
        return d;
    }();
    return dir;
}

inline void writeFile(const std::filesystem::path& path, const std::string& bytes)
{
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), std::streamsize(bytes.size()));
}

} // namespace rtlab::fuzz
