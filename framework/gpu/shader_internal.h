#pragma once
// Private to the gpu module: include resolution, cache keys and cache files shared by the
// shader compiler's .cpp files.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "gpu/shader_compiler.h"

namespace rtlab::gpu::detail {

//! Where `#include "name"` (quoted) or `#include <name>` leads from the file `includer`:
//! quoted names are looked up next to the includer first, then in `includeDirs` in order.
//! Returns an absolute, normalised path, or an empty path when no such file exists.
std::filesystem::path resolveInclude(std::string_view name, bool quoted,
                                     const std::filesystem::path& includer,
                                     const std::vector<std::filesystem::path>& includeDirs);

//! Reads a whole file; nullopt when it cannot be read.
std::optional<std::string> readFileText(const std::filesystem::path& path);

//! The cache key of a source and everything it reaches through #include.
struct ShaderKey {
    std::string key;                                 //!< 32 hex digits
    std::vector<std::filesystem::path> dependencies; //!< resolved included files, found order
};

//! Hashes the source, the contents of all files its #include directives reach (directives are
//! found by scanning lines, also in inactive #if branches), the defines and the compiler
//! version. A non-empty `stageTag` (the stage of non-compute shaders) is hashed as well.
ShaderKey computeShaderKey(std::string_view source, const std::filesystem::path& sourcePath,
                           const std::vector<ShaderDefine>& defines,
                           const std::vector<std::filesystem::path>& includeDirs,
                           std::string_view stageTag = {});

//! The cached SPIR-V for `key`, or nullopt when absent or corrupt.
std::optional<std::vector<std::uint32_t>> readCachedSpirv(const std::filesystem::path& dir,
                                                          const std::string& key);

//! Stores SPIR-V under `key` atomically (write then rename). Returns an error description,
//! empty on success; failing to cache does not fail a compilation.
std::string writeCachedSpirv(const std::filesystem::path& dir, const std::string& key,
                             const std::vector<std::uint32_t>& spirv);

} // namespace rtlab::gpu::detail
