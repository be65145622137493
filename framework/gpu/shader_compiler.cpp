// Compiling GLSL shaders with glslang, behind the SPIR-V cache.

#include "gpu/shader_compiler.h"

#include <glslang/Public/ResourceLimits.h>
#include <glslang/Public/ShaderLang.h>
#include <glslang/SPIRV/GlslangToSpv.h>

#include <cctype>
#include <chrono>
#include <memory>
#include <optional>

#include "core/error.h"
#include "gpu/shader_internal.h"

namespace rtlab::gpu {

namespace fs = std::filesystem;

namespace {

constexpr glslang::EShTargetClientVersion kClientVersion = glslang::EShTargetVulkan_1_1;
constexpr glslang::EShTargetLanguageVersion kSpirvVersion = glslang::EShTargetSpv_1_3;
constexpr int kDefaultGlslVersion = 450; // for sources without #version

// glslang needs process-wide initialisation once; it is undone at exit.
void initializeGlslang()
{
    struct Process {
        Process() { glslang::InitializeProcess(); }
        ~Process() { glslang::FinalizeProcess(); }
    };
    static Process process;
}

// Resolves #include through detail::resolveInclude, so the compiler sees exactly the files
// the cache key was computed from.
class FileIncluder : public glslang::TShader::Includer {
public:
    explicit FileIncluder(const std::vector<fs::path>& includeDirs) : mIncludeDirs(includeDirs) {}

    IncludeResult* includeLocal(const char* name, const char* includer, size_t) override
    {
        return open(detail::resolveInclude(name, true, includer, {}));
    }
    IncludeResult* includeSystem(const char* name, const char*, size_t) override
    {
        return open(detail::resolveInclude(name, false, {}, mIncludeDirs));
    }
    void releaseInclude(IncludeResult* result) override
    {
        if (result != nullptr) {
            delete static_cast<std::string*>(result->userData);
            delete result;
        }
    }

private:
    IncludeResult* open(const fs::path& path)
    {
        if (path.empty())
            return nullptr;
        std::optional<std::string> text = detail::readFileText(path);
        if (!text)
            return nullptr;
        auto* content = new std::string(std::move(*text));
        return new IncludeResult(path.string(), content->data(), content->size(), content);
    }

    const std::vector<fs::path>& mIncludeDirs;
};

bool isIdentifier(const std::string& name)
{
    if (name.empty() || std::isdigit(static_cast<unsigned char>(name[0])))
        return false;
    for (char c : name) {
        if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_')
            return false;
    }
    return true;
}

std::string makePreamble(const std::vector<ShaderDefine>& defines, const fs::path& sourcePath)
{
    std::string preamble = "#extension GL_GOOGLE_include_directive : require\n";
    for (const ShaderDefine& d : defines) {
        if (!isIdentifier(d.name))
            throw InputError(SourceLocation{sourcePath.string(), 0, 0},
                             "shader define '" + d.name + "' is not a valid identifier");
        if (d.value.find('\n') != std::string::npos)
            throw InputError(SourceLocation{sourcePath.string(), 0, 0},
                             "the value of shader define '" + d.name + "' contains a newline");
        preamble += "#define " + d.name + " " + d.value + "\n";
    }
    return preamble;
}

std::string trim(std::string s)
{
    while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back())))
        s.pop_back();
    std::size_t start = 0;
    while (start < s.size() && std::isspace(static_cast<unsigned char>(s[start])))
        ++start;
    return s.substr(start);
}

struct LocatedError {
    std::string file;
    int line = 0;
    std::string message;
};

// Splits "<file>:<line>: <message>" at the first ':' that is followed by digits and ": ".
std::optional<LocatedError> parseLocatedError(const std::string& text)
{
    for (std::size_t colon = text.find(':'); colon != std::string::npos;
         colon = text.find(':', colon + 1)) {
        std::size_t p = colon + 1;
        while (p < text.size() && std::isdigit(static_cast<unsigned char>(text[p])))
            ++p;
        if (p == colon + 1 || text.compare(p, 2, ": ") != 0)
            continue;
        return LocatedError{text.substr(0, colon), std::stoi(text.substr(colon + 1, p - colon - 1)),
                            trim(text.substr(p + 2))};
    }
    return std::nullopt;
}

// Turns glslang's log ("ERROR: file:line: message" lines, then a summary) into an InputError
// located at the first error; further errors are listed in the message.
[[noreturn]] void throwCompileError(const std::string& log, const fs::path& sourcePath)
{
    std::vector<LocatedError> errors;
    std::size_t start = 0;
    while (start < log.size()) {
        std::size_t end = log.find('\n', start);
        if (end == std::string::npos)
            end = log.size();
        const std::string line = log.substr(start, end - start);
        start = end + 1;
        constexpr std::string_view kError = "ERROR: ";
        if (line.rfind(kError, 0) != 0)
            continue;
        std::optional<LocatedError> error = parseLocatedError(line.substr(kError.size()));
        if (error && error->message != "'' : compilation terminated")
            errors.push_back(std::move(*error));
    }
    if (errors.empty())
        throw InputError(SourceLocation{sourcePath.string(), 0, 0},
                         "shader compilation failed: " + trim(log));
    for (LocatedError& e : errors) {
        if (e.file.empty() || e.file == "0") // an unnamed string: the main source
            e.file = sourcePath.string();
    }
    std::string message = "shader compilation failed: " + errors.front().message;
    for (std::size_t k = 1; k < errors.size(); ++k)
        message += "\n" + errors[k].file + ":" + std::to_string(errors[k].line) +
                   ": error: " + errors[k].message;
    throw InputError(SourceLocation{errors.front().file, errors.front().line, 0}, message);
}

EShLanguage toGlslangStage(ShaderStage stage)
{
    switch (stage) {
    case ShaderStage::Vertex:
        return EShLangVertex;
    case ShaderStage::Fragment:
        return EShLangFragment;
    case ShaderStage::Compute:
        break;
    }
    return EShLangCompute;
}

std::vector<std::uint32_t> runGlslang(std::string_view source, const fs::path& sourcePath,
                                      ShaderStage shaderStage,
                                      const std::vector<ShaderDefine>& defines,
                                      const std::vector<fs::path>& includeDirs,
                                      std::string& warnings)
{
    initializeGlslang();
    const std::string preamble = makePreamble(defines, sourcePath);
    const std::string name = sourcePath.string();
    const char* strings[] = {source.data()};
    const int lengths[] = {static_cast<int>(source.size())};
    const char* names[] = {name.c_str()};

    const EShLanguage stage = toGlslangStage(shaderStage);
    glslang::TShader shader(stage);
    shader.setStringsWithLengthsAndNames(strings, lengths, names, 1);
    shader.setPreamble(preamble.c_str());
    shader.setEnvInput(glslang::EShSourceGlsl, stage, glslang::EShClientVulkan, 100);
    shader.setEnvClient(glslang::EShClientVulkan, kClientVersion);
    shader.setEnvTarget(glslang::EShTargetSpv, kSpirvVersion);
    const auto messages = static_cast<EShMessages>(EShMsgSpvRules | EShMsgVulkanRules);
    FileIncluder includer(includeDirs);
    if (!shader.parse(GetDefaultResources(), kDefaultGlslVersion, false, messages, includer))
        throwCompileError(shader.getInfoLog(), sourcePath);

    glslang::TProgram program;
    program.addShader(&shader);
    if (!program.link(messages))
        throwCompileError(program.getInfoLog(), sourcePath);

    std::vector<std::uint32_t> spirv;
    spv::SpvBuildLogger logger;
    glslang::SpvOptions options;
    options.disableOptimizer = false;
    options.validate = true;
    glslang::GlslangToSpv(*program.getIntermediate(stage), spirv, &logger, &options);
    warnings = trim(std::string(shader.getInfoLog()) + "\n" + logger.getAllMessages());
    if (spirv.empty())
        throw InputError(SourceLocation{name, 0, 0},
                         "shader compilation produced no SPIR-V: " + warnings);
    return spirv;
}

} // namespace

ShaderStage getShaderStage(const fs::path& path)
{
    const fs::path extension = path.extension();
    if (extension == ".vert")
        return ShaderStage::Vertex;
    if (extension == ".frag")
        return ShaderStage::Fragment;
    return ShaderStage::Compute;
}

const char* getShaderStageName(ShaderStage stage)
{
    switch (stage) {
    case ShaderStage::Compute:
        return "compute";
    case ShaderStage::Vertex:
        return "vertex";
    case ShaderStage::Fragment:
        return "fragment";
    }
    return "?";
}

std::string getShaderCompilerVersion()
{
    const glslang::Version v = glslang::GetVersion();
    return "glslang " + std::to_string(v.major) + "." + std::to_string(v.minor) + "." +
           std::to_string(v.patch) + (v.flavor != nullptr ? v.flavor : "") +
           ", vulkan1.1/spv1.3, spirv-opt, glsl" + std::to_string(kDefaultGlslVersion);
}

ShaderCompiler::ShaderCompiler(ShaderCompilerOptions options) : mOptions(std::move(options))
{
    mCacheDir = mOptions.cacheDir.empty() ? getDefaultShaderCacheDir() : mOptions.cacheDir;
}

CompiledShader ShaderCompiler::compileFile(const fs::path& path,
                                           const std::vector<ShaderDefine>& defines) const
{
    const auto start = std::chrono::steady_clock::now();
    std::optional<std::string> source = detail::readFileText(path);
    if (!source || !fs::is_regular_file(path))
        throw InputError(SourceLocation{path.string(), 0, 0}, "cannot read shader file");
    CompiledShader result = compileSource(*source, path, defines);
    result.compileMs =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    return result;
}

CompiledShader ShaderCompiler::compileSource(std::string_view source, const fs::path& virtualPath,
                                             const std::vector<ShaderDefine>& defines) const
{
    const auto start = std::chrono::steady_clock::now();
    CompiledShader result;
    result.sourcePath = virtualPath;
    result.stage = getShaderStage(virtualPath);
    // Compute shaders carry no stage in their key, so their cache entries stay valid.
    const std::string_view stageTag = result.stage == ShaderStage::Compute
                                          ? std::string_view()
                                          : getShaderStageName(result.stage);
    detail::ShaderKey key =
        detail::computeShaderKey(source, virtualPath, defines, mOptions.includeDirs, stageTag);
    result.cacheKey = key.key;
    result.dependencies = std::move(key.dependencies);

    if (mOptions.useCache) {
        if (auto cached = detail::readCachedSpirv(mCacheDir, result.cacheKey)) {
            result.spirv = std::move(*cached);
            result.cacheHit = true;
        }
    }
    if (!result.cacheHit) {
        result.spirv = runGlslang(source, virtualPath, result.stage, defines, mOptions.includeDirs,
                                  result.warnings);
        if (mOptions.useCache) {
            const std::string problem =
                detail::writeCachedSpirv(mCacheDir, result.cacheKey, result.spirv);
            if (!problem.empty())
                result.warnings +=
                    (result.warnings.empty() ? "" : "\n") + ("SPIR-V not cached: " + problem);
        }
    }
    result.compileMs =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    return result;
}

} // namespace rtlab::gpu
