#pragma once
// GLSL shaders compiled to SPIR-V (Vulkan 1.1, SPIR-V 1.3) with glslang at run time. The stage
// follows the file extension: .vert vertex, .frag fragment, anything else compute.
//
// #include "file" is searched next to the including file, then in the include directories;
// #include <file> only in the include directories. GL_GOOGLE_include_directive is enabled
// automatically.
//
// Results are cached on disk. The key hashes the main source, the content of every file that
// #include directives reach (found by scanning the sources, including directives in inactive
// #if branches, so the key may depend on more files than the compilation uses but never on
// fewer), the defines in order, and the compiler version and settings.

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace rtlab::gpu {

//! The pipeline stage a GLSL source is compiled for.
enum class ShaderStage { Compute, Vertex, Fragment };

//! The stage of a source file by its extension: ".vert" Vertex, ".frag" Fragment, anything else
//! (".comp", ".glsl", none) Compute.
ShaderStage getShaderStage(const std::filesystem::path& path);

//! "compute", "vertex", "fragment".
const char* getShaderStageName(ShaderStage stage);

//! A preprocessor definition: #define name value (value may be empty).
struct ShaderDefine {
    std::string name;
    std::string value;
};

//! Settings of a ShaderCompiler.
struct ShaderCompilerOptions {
    std::vector<std::filesystem::path> includeDirs; //!< searched in order
    //! Where SPIR-V is cached. Empty: getDefaultShaderCacheDir().
    std::filesystem::path cacheDir;
    bool useCache = true; //!< false: always compile, never read or write the cache
};

//! The result of a compilation.
struct CompiledShader {
    std::vector<std::uint32_t> spirv;
    std::filesystem::path sourcePath; //!< as given (or the virtual name of an in-memory source)
    ShaderStage stage = ShaderStage::Compute;        //!< from the extension of sourcePath
    std::vector<std::filesystem::path> dependencies; //!< files reached by #include, resolved
    std::string cacheKey;                            //!< 32 hex digits
    bool cacheHit = false;  //!< SPIR-V came from the cache; glslang did not run
    double compileMs = 0.0; //!< wall time of the whole call (reading, hashing, compiling, caching)
    std::string warnings;   //!< glslang's warnings, empty when there are none
};

//! Compiles shaders (stage by file extension, see getShaderStage()). Cheap to create; holds no
//! glslang state between calls.
class ShaderCompiler {
public:
    explicit ShaderCompiler(ShaderCompilerOptions options = {});

    //! Compiles a GLSL shader file. Throws rtlab::InputError naming the file and line
    //! (of the included file, where the error is in one) with glslang's message when the shader
    //! does not compile, or naming the file when it cannot be read.
    CompiledShader compileFile(const std::filesystem::path& path,
                               const std::vector<ShaderDefine>& defines = {}) const;

    //! Compiles GLSL held in memory. `virtualPath` names it in errors, its extension selects
    //! the stage, and its directory is where #include "..." looks first.
    CompiledShader compileSource(std::string_view source, const std::filesystem::path& virtualPath,
                                 const std::vector<ShaderDefine>& defines = {}) const;

    const ShaderCompilerOptions& getOptions() const { return mOptions; }
    //! The directory in use for the cache.
    const std::filesystem::path& getCacheDir() const { return mCacheDir; }

private:
    ShaderCompilerOptions mOptions;
    std::filesystem::path mCacheDir;
};

//! $RTLAB_CACHE_DIR/spirv, else $XDG_CACHE_HOME/rtlab/spirv, else $HOME/.cache/rtlab/spirv,
//! else <temp dir>/rtlab/spirv.
std::filesystem::path getDefaultShaderCacheDir();

//! Identifies the compiler and its settings, e.g. "glslang 12.0.0, vulkan1.1/spv1.3, opt".
//! Part of every cache key.
std::string getShaderCompilerVersion();

//! A folder of shaders in the source tree: $RTLAB_SOURCE_DIR/`relative` when that variable is set
//! (shaders edited in another checkout, or a moved tree), otherwise `builtIn`, the folder the
//! code was compiled from (a compile definition such as RTLAB_TECHNIQUE_DIR "/shaders").
std::filesystem::path findShaderDir(const std::filesystem::path& relative, const std::filesystem::path& builtIn);

//! Directory of the shaders that ship with the framework (framework/gpu/shaders):
//! $RTLAB_SOURCE_DIR/framework/gpu/shaders when that variable is set, otherwise the path
//! of the source tree the library was built from.
std::filesystem::path getBuiltinShaderDir();

} // namespace rtlab::gpu
