// Include resolution, cache keys and the on-disk SPIR-V cache.

#include "gpu/shader_internal.h"

#include <atomic>
#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>
#include <unistd.h>

#include "core/hash.h"

namespace rtlab::gpu {

namespace fs = std::filesystem;

namespace {

fs::path readPathFromEnv(const char* name)
{
    const char* value = std::getenv(name);
    return value != nullptr && *value != '\0' ? fs::path(value) : fs::path();
}

} // namespace

fs::path getDefaultShaderCacheDir()
{
    if (fs::path dir = readPathFromEnv("RTLAB_CACHE_DIR"); !dir.empty())
        return dir / "spirv";
    if (fs::path dir = readPathFromEnv("XDG_CACHE_HOME"); !dir.empty())
        return dir / "rtlab" / "spirv";
    if (fs::path dir = readPathFromEnv("HOME"); !dir.empty())
        return dir / ".cache" / "rtlab" / "spirv";
    return fs::temp_directory_path() / "rtlab" / "spirv";
}

fs::path findShaderDir(const fs::path& relative, const fs::path& builtIn)
{
    if (fs::path root = readPathFromEnv("RTLAB_SOURCE_DIR"); !root.empty())
        return root / relative;
    return builtIn;
}

fs::path getBuiltinShaderDir()
{
    return findShaderDir("framework/gpu/shaders", RTLAB_GPU_SHADER_DIR);
}

namespace detail {

namespace {

struct IncludeDirective {
    std::string name;
    bool quoted = true;
};

bool isBlank(char c)
{
    return c == ' ' || c == '\t';
}

// Every `#include "x"` / `#include <x>` line, in order.
std::vector<IncludeDirective> findIncludeDirectives(std::string_view text)
{
    std::vector<IncludeDirective> found;
    std::size_t lineStart = 0;
    while (lineStart < text.size()) {
        std::size_t lineEnd = text.find('\n', lineStart);
        if (lineEnd == std::string_view::npos)
            lineEnd = text.size();
        const std::string_view line = text.substr(lineStart, lineEnd - lineStart);
        lineStart = lineEnd + 1;

        std::size_t p = 0;
        while (p < line.size() && isBlank(line[p]))
            ++p;
        if (p >= line.size() || line[p] != '#')
            continue;
        ++p;
        while (p < line.size() && isBlank(line[p]))
            ++p;
        constexpr std::string_view kInclude = "include";
        if (line.substr(p, kInclude.size()) != kInclude)
            continue;
        p += kInclude.size();
        while (p < line.size() && isBlank(line[p]))
            ++p;
        if (p >= line.size() || (line[p] != '"' && line[p] != '<'))
            continue;
        const bool quoted = line[p] == '"';
        const std::size_t close = line.find(quoted ? '"' : '>', p + 1);
        if (close == std::string_view::npos)
            continue;
        found.push_back({std::string(line.substr(p + 1, close - p - 1)), quoted});
    }
    return found;
}

struct KeyScanner {
    const std::vector<fs::path>& includeDirs;
    Hasher hasher;
    std::map<fs::path, std::size_t> visited; // resolved path -> index in dependencies
    std::vector<fs::path> dependencies;

    void scan(std::string_view text, const fs::path& file, int depth)
    {
        for (const IncludeDirective& d : findIncludeDirectives(text)) {
            hasher.add(d.quoted ? "quoted" : "angled").add(d.name);
            const fs::path resolved = resolveInclude(d.name, d.quoted, file, includeDirs);
            if (resolved.empty()) {
                hasher.add("<missing>");
                continue;
            }
            if (auto it = visited.find(resolved); it != visited.end()) {
                hasher.add("<seen>").addValue(static_cast<std::uint64_t>(it->second));
                continue;
            }
            const std::optional<std::string> content = readFileText(resolved);
            if (!content) {
                hasher.add("<unreadable>");
                continue;
            }
            visited.emplace(resolved, dependencies.size());
            dependencies.push_back(resolved);
            hasher.add(*content);
            if (depth < 64)
                scan(*content, resolved, depth + 1);
        }
    }
};

std::atomic<unsigned> gTempCounter{0};

} // namespace

fs::path resolveInclude(std::string_view name, bool quoted, const fs::path& includer,
                        const std::vector<fs::path>& includeDirs)
{
    std::error_code ec;
    auto tryPath = [&](const fs::path& candidate) -> fs::path {
        if (fs::is_regular_file(candidate, ec))
            return fs::absolute(candidate, ec).lexically_normal();
        return {};
    };
    const fs::path relative(name);
    if (relative.is_absolute())
        return tryPath(relative);
    if (quoted) {
        if (fs::path p = tryPath(includer.parent_path() / relative); !p.empty())
            return p;
    }
    for (const fs::path& dir : includeDirs) {
        if (fs::path p = tryPath(dir / relative); !p.empty())
            return p;
    }
    return {};
}

std::optional<std::string> readFileText(const fs::path& path)
{
    std::ifstream in(path, std::ios::binary);
    if (!in)
        return std::nullopt;
    std::ostringstream text;
    text << in.rdbuf();
    if (in.bad())
        return std::nullopt;
    return text.str();
}

ShaderKey computeShaderKey(std::string_view source, const fs::path& sourcePath,
                           const std::vector<ShaderDefine>& defines,
                           const std::vector<fs::path>& includeDirs, std::string_view stageTag)
{
    KeyScanner scanner{includeDirs, Hasher(), {}, {}};
    scanner.hasher.add("rtlab-spirv-cache/1").add(getShaderCompilerVersion()).add(source);
    if (!stageTag.empty())
        scanner.hasher.add("stage").add(stageTag);
    scanner.hasher.addValue(static_cast<std::uint64_t>(defines.size()));
    for (const ShaderDefine& d : defines)
        scanner.hasher.add(d.name).add(d.value);
    scanner.scan(source, sourcePath, 0);
    return {scanner.hasher.hexDigest(), std::move(scanner.dependencies)};
}

std::optional<std::vector<std::uint32_t>> readCachedSpirv(const fs::path& dir,
                                                          const std::string& key)
{
    std::ifstream in(dir / (key + ".spv"), std::ios::binary | std::ios::ate);
    if (!in)
        return std::nullopt;
    const std::streamoff size = in.tellg();
    constexpr std::uint32_t kSpirvMagic = 0x07230203u;
    if (size < 20 || size % 4 != 0)
        return std::nullopt;
    std::vector<std::uint32_t> words(static_cast<std::size_t>(size) / 4);
    in.seekg(0);
    if (!in.read(reinterpret_cast<char*>(words.data()), size) || words[0] != kSpirvMagic)
        return std::nullopt;
    return words;
}

std::string writeCachedSpirv(const fs::path& dir, const std::string& key,
                             const std::vector<std::uint32_t>& spirv)
{
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (ec)
        return "cannot create " + dir.string() + ": " + ec.message();
    const fs::path final = dir / (key + ".spv");
    const fs::path temp = dir / (key + ".spv.tmp." + std::to_string(::getpid()) + "." +
                                 std::to_string(gTempCounter.fetch_add(1)));
    {
        std::ofstream out(temp, std::ios::binary | std::ios::trunc);
        out.write(reinterpret_cast<const char*>(spirv.data()),
                  static_cast<std::streamsize>(spirv.size() * sizeof(std::uint32_t)));
        if (!out) {
            fs::remove(temp, ec);
            return "cannot write " + temp.string();
        }
    }
    fs::rename(temp, final, ec);
    if (ec) {
        fs::remove(temp, ec);
        return "cannot rename into " + final.string();
    }
    return {};
}

} // namespace detail
} // namespace rtlab::gpu
