// Run-time GLSL compilation: includes, defines, errors with file and line, and the SPIR-V
// cache (hit on the second compile, miss after any input changes).

#include <filesystem>
#include <fstream>
#include <string>

#include "core/error.h"
#include "gpu/shader_compiler.h"
#include "gpu_test_support.h"

namespace rtlab::gpu::test {
namespace {

namespace fs = std::filesystem;

constexpr std::string_view kMainShader = R"(#version 450
#include "common.glsl"
#include <lib/util.glsl>
layout(local_size_x = 1) in;
layout(set = 0, binding = 0) buffer Out { uint values[]; };
void main() { values[0] = commonValue() + utilValue() + VALUE; }
)";

constexpr std::string_view kCommon = "uint commonValue() { return 10u; }\n";
constexpr std::string_view kUtil = R"(#include "util_inner.glsl"
uint utilValue() { return innerValue() * 2u; }
)";
constexpr std::string_view kUtilInner = "uint innerValue() { return 100u; }\n";

// A shader tree: main.comp and common.glsl in src/, lib/util.glsl (which includes
// util_inner.glsl next to itself) in an include directory.
struct ShaderTree {
    TempDir dir{"shader-tree"};
    TempDir cache{"shader-cache"};
    fs::path main = dir.writeFile("src/main.comp", kMainShader);
    fs::path common = dir.writeFile("src/common.glsl", kCommon);
    fs::path util = dir.writeFile("include/lib/util.glsl", kUtil);
    fs::path utilInner = dir.writeFile("include/lib/util_inner.glsl", kUtilInner);

    ShaderCompiler makeCompiler(bool useCache = true) const
    {
        ShaderCompilerOptions options;
        options.includeDirs = {dir.getPath() / "include"};
        options.cacheDir = cache.getPath();
        options.useCache = useCache;
        return ShaderCompiler(options);
    }
};

const std::vector<ShaderDefine> kValue1 = {{"VALUE", "1u"}};

TEST(ShaderCompiler, CompilesWithIncludesAndDefines)
{
    ShaderTree tree;
    const CompiledShader shader = tree.makeCompiler().compileFile(tree.main, kValue1);
    ASSERT_GE(shader.spirv.size(), 5u);
    EXPECT_EQ(shader.spirv[0], 0x07230203u);
    EXPECT_FALSE(shader.cacheHit);
    EXPECT_EQ(shader.cacheKey.size(), 32u);
    EXPECT_GT(shader.compileMs, 0.0);
    EXPECT_EQ(shader.sourcePath, tree.main);
    ASSERT_EQ(shader.dependencies.size(), 3u);
    EXPECT_EQ(shader.dependencies[0], fs::absolute(tree.common).lexically_normal());
    EXPECT_EQ(shader.dependencies[1], fs::absolute(tree.util).lexically_normal());
    EXPECT_EQ(shader.dependencies[2], fs::absolute(tree.utilInner).lexically_normal());
}

TEST(ShaderCompiler, SecondCompileHitsTheCache)
{
    ShaderTree tree;
    const CompiledShader first = tree.makeCompiler().compileFile(tree.main, kValue1);
    EXPECT_FALSE(first.cacheHit);
    EXPECT_TRUE(fs::exists(tree.cache.getPath() / (first.cacheKey + ".spv")));

    // A new compiler object reads the same on-disk cache.
    const CompiledShader second = tree.makeCompiler().compileFile(tree.main, kValue1);
    EXPECT_TRUE(second.cacheHit);
    EXPECT_EQ(second.cacheKey, first.cacheKey);
    EXPECT_EQ(second.spirv, first.spirv);
    EXPECT_EQ(second.dependencies, first.dependencies);
    EXPECT_GE(second.compileMs, 0.0);
}

TEST(ShaderCompiler, ChangingAnIncludedFileMissesTheCache)
{
    ShaderTree tree;
    const ShaderCompiler compiler = tree.makeCompiler();
    const CompiledShader original = compiler.compileFile(tree.main, kValue1);
    ASSERT_TRUE(compiler.compileFile(tree.main, kValue1).cacheHit);

    tree.dir.writeFile("src/common.glsl", "uint commonValue() { return 11u; }\n");
    const CompiledShader changedDirect = compiler.compileFile(tree.main, kValue1);
    EXPECT_FALSE(changedDirect.cacheHit);
    EXPECT_NE(changedDirect.cacheKey, original.cacheKey);
    EXPECT_NE(changedDirect.spirv, original.spirv);
    EXPECT_TRUE(compiler.compileFile(tree.main, kValue1).cacheHit);

    // A file two levels down, reached through the include directory.
    tree.dir.writeFile("include/lib/util_inner.glsl", "uint innerValue() { return 101u; }\n");
    const CompiledShader changedNested = compiler.compileFile(tree.main, kValue1);
    EXPECT_FALSE(changedNested.cacheHit);
    EXPECT_NE(changedNested.cacheKey, changedDirect.cacheKey);

    // Restoring the contents finds the first entry again.
    tree.dir.writeFile("src/common.glsl", kCommon);
    tree.dir.writeFile("include/lib/util_inner.glsl", kUtilInner);
    const CompiledShader restored = compiler.compileFile(tree.main, kValue1);
    EXPECT_TRUE(restored.cacheHit);
    EXPECT_EQ(restored.cacheKey, original.cacheKey);
}

TEST(ShaderCompiler, ChangingTheMainSourceMissesTheCache)
{
    ShaderTree tree;
    const ShaderCompiler compiler = tree.makeCompiler();
    const CompiledShader original = compiler.compileFile(tree.main, kValue1);
    std::string edited(kMainShader);
    edited += "// a comment changes the key\n";
    tree.dir.writeFile("src/main.comp", edited);
    const CompiledShader changed = compiler.compileFile(tree.main, kValue1);
    EXPECT_FALSE(changed.cacheHit);
    EXPECT_NE(changed.cacheKey, original.cacheKey);
}

TEST(ShaderCompiler, ChangingADefineMissesTheCache)
{
    ShaderTree tree;
    const ShaderCompiler compiler = tree.makeCompiler();
    const CompiledShader one = compiler.compileFile(tree.main, kValue1);
    EXPECT_FALSE(one.cacheHit);
    EXPECT_TRUE(compiler.compileFile(tree.main, kValue1).cacheHit);

    const CompiledShader two = compiler.compileFile(tree.main, {{"VALUE", "2u"}});
    EXPECT_FALSE(two.cacheHit);
    EXPECT_NE(two.cacheKey, one.cacheKey);
    EXPECT_NE(two.spirv, one.spirv);

    const CompiledShader extra = compiler.compileFile(tree.main, {{"VALUE", "1u"}, {"EXTRA", ""}});
    EXPECT_FALSE(extra.cacheHit);
    EXPECT_NE(extra.cacheKey, one.cacheKey);

    EXPECT_TRUE(compiler.compileFile(tree.main, {{"VALUE", "2u"}}).cacheHit);
}

TEST(ShaderCompiler, CompilerVersionIsPartOfTheKey)
{
    EXPECT_EQ(getShaderCompilerVersion().rfind("glslang ", 0), 0u) << getShaderCompilerVersion();
    // The key of an in-memory source without includes is fully determined by the source, the
    // defines and the compiler version; it is stable across compiler objects.
    TempDir cache("version-cache");
    ShaderCompilerOptions options;
    options.cacheDir = cache.getPath();
    const std::string source = "#version 450\nlayout(local_size_x = 1) in;\nvoid main() {}\n";
    const CompiledShader a = ShaderCompiler(options).compileSource(source, "a.comp");
    const CompiledShader b = ShaderCompiler(options).compileSource(source, "b.comp");
    EXPECT_EQ(a.cacheKey, b.cacheKey);
    EXPECT_TRUE(b.cacheHit);
}

TEST(ShaderCompiler, DisabledCacheNeverReadsOrWrites)
{
    ShaderTree tree;
    const ShaderCompiler compiler = tree.makeCompiler(false);
    EXPECT_FALSE(compiler.compileFile(tree.main, kValue1).cacheHit);
    EXPECT_FALSE(compiler.compileFile(tree.main, kValue1).cacheHit);
    EXPECT_TRUE(fs::is_empty(tree.cache.getPath()));
}

TEST(ShaderCompiler, CorruptCacheEntryIsRecompiled)
{
    ShaderTree tree;
    const ShaderCompiler compiler = tree.makeCompiler();
    const CompiledShader first = compiler.compileFile(tree.main, kValue1);
    tree.cache.writeFile(first.cacheKey + ".spv", "not spir-v at all");
    const CompiledShader again = compiler.compileFile(tree.main, kValue1);
    EXPECT_FALSE(again.cacheHit);
    EXPECT_EQ(again.spirv, first.spirv);
    EXPECT_TRUE(compiler.compileFile(tree.main, kValue1).cacheHit);
}

TEST(ShaderCompiler, CompileErrorNamesFileLineAndGlslangMessage)
{
    TempDir dir("compile-error");
    const fs::path path = dir.writeFile("broken.comp", R"(#version 450
layout(local_size_x = 1) in;
layout(set = 0, binding = 0) buffer Out { float values[]; };

void main()
{
    values[0] = undeclaredThing;
    values[1] = secondMistake;
}
)");
    ShaderCompilerOptions options;
    options.cacheDir = dir.getPath() / "cache";
    try {
        ShaderCompiler(options).compileFile(path);
        FAIL() << "expected rtlab::InputError";
    } catch (const InputError& e) {
        EXPECT_EQ(e.location().file, path.string());
        EXPECT_EQ(e.location().line, 7);
        EXPECT_NE(e.message().find("undeclaredThing"), std::string::npos) << e.what();
        EXPECT_NE(e.message().find("undeclared identifier"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find(path.string() + ":7: error: "), std::string::npos)
            << e.what();
        // glslang stops at the first error; its trailing noise is not repeated.
        EXPECT_EQ(e.message().find("compilation terminated"), std::string::npos) << e.what();
    }
    EXPECT_FALSE(fs::exists(dir.getPath() / "cache") && !fs::is_empty(dir.getPath() / "cache"));
}

TEST(ShaderCompiler, CompileErrorInAnIncludedFileNamesThatFile)
{
    TempDir dir("include-error");
    const fs::path header =
        dir.writeFile("helpers.glsl", "// helpers\nfloat twice(float x)\n{ return 2.0 * y; }\n");
    const fs::path path = dir.writeFile("main.comp", R"(#version 450
#include "helpers.glsl"
layout(local_size_x = 1) in;
void main() {}
)");
    ShaderCompilerOptions options;
    options.cacheDir = dir.getPath() / "cache";
    try {
        ShaderCompiler(options).compileFile(path);
        FAIL() << "expected rtlab::InputError";
    } catch (const InputError& e) {
        EXPECT_EQ(fs::path(e.location().file), fs::absolute(header).lexically_normal()) << e.what();
        EXPECT_EQ(e.location().line, 3) << e.what();
        EXPECT_NE(e.message().find("'y'"), std::string::npos) << e.what();
    }
}

TEST(ShaderCompiler, MissingIncludeIsAnInputError)
{
    TempDir dir("missing-include");
    const fs::path path = dir.writeFile(
        "main.comp", "#version 450\n#include \"not_there.glsl\"\nlayout(local_size_x = 1) in;\n"
                     "void main() {}\n");
    ShaderCompilerOptions options;
    options.cacheDir = dir.getPath() / "cache";
    try {
        ShaderCompiler(options).compileFile(path);
        FAIL() << "expected rtlab::InputError";
    } catch (const InputError& e) {
        EXPECT_EQ(e.location().file, path.string());
        EXPECT_EQ(e.location().line, 2);
        EXPECT_NE(e.message().find("not_there.glsl"), std::string::npos) << e.what();
    }
}

TEST(ShaderCompiler, UnreadableFileAndBadDefinesAreInputErrors)
{
    TempDir dir("unreadable");
    ShaderCompilerOptions options;
    options.cacheDir = dir.getPath() / "cache";
    const ShaderCompiler compiler(options);
    try {
        compiler.compileFile(dir.getPath() / "nope.comp");
        FAIL() << "expected rtlab::InputError";
    } catch (const InputError& e) {
        EXPECT_EQ(e.location().file, (dir.getPath() / "nope.comp").string());
    }
    const fs::path path =
        dir.writeFile("ok.comp", "#version 450\nlayout(local_size_x = 1) in;\nvoid main() {}\n");
    EXPECT_THROW(compiler.compileFile(path, {{"1BAD", "1"}}), InputError);
    EXPECT_THROW(compiler.compileFile(path, {{"GOOD", "1\n#error"}}), InputError);
}

TEST(ShaderCompiler, DefaultCacheDirFollowsTheEnvironment)
{
    {
        ScopedEnv rtlab("RTLAB_CACHE_DIR", "/tmp/rtlab-root");
        ScopedEnv xdg("XDG_CACHE_HOME", "/tmp/xdg");
        EXPECT_EQ(getDefaultShaderCacheDir(), fs::path("/tmp/rtlab-root/spirv"));
    }
    {
        ScopedEnv rtlab("RTLAB_CACHE_DIR", std::nullopt);
        ScopedEnv xdg("XDG_CACHE_HOME", "/tmp/xdg");
        EXPECT_EQ(getDefaultShaderCacheDir(), fs::path("/tmp/xdg/rtlab/spirv"));
    }
    {
        ScopedEnv rtlab("RTLAB_CACHE_DIR", std::nullopt);
        ScopedEnv xdg("XDG_CACHE_HOME", std::nullopt);
        ScopedEnv home("HOME", "/home/someone");
        EXPECT_EQ(getDefaultShaderCacheDir(), fs::path("/home/someone/.cache/rtlab/spirv"));
    }
    ScopedEnv rtlab("RTLAB_CACHE_DIR", "/tmp/rtlab-root");
    EXPECT_EQ(ShaderCompiler().getCacheDir(), fs::path("/tmp/rtlab-root/spirv"));
    ShaderCompilerOptions options;
    options.cacheDir = "/somewhere/else";
    EXPECT_EQ(ShaderCompiler(options).getCacheDir(), fs::path("/somewhere/else"));
}

TEST(ShaderCompiler, BuiltinShaderDirHoldsTheSmokeShader)
{
    EXPECT_TRUE(fs::is_regular_file(getBuiltinShaderDir() / "smoke.comp")) << getBuiltinShaderDir();
}

} // namespace
} // namespace rtlab::gpu::test
