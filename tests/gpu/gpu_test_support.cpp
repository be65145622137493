#include "gpu_test_support.h"

#include <atomic>
#include <cstdlib>
#include <fstream>
#include <unistd.h>

namespace rtlab::gpu::test {

namespace fs = std::filesystem;

fs::path getTestShaderDir()
{
    if (const char* root = std::getenv("RTLAB_SOURCE_DIR"); root != nullptr && *root != '\0')
        return fs::path(root) / "tests" / "gpu" / "shaders";
    return fs::path(RTLAB_GPU_TEST_SHADER_DIR);
}

namespace {
std::atomic<int> gTempCounter{0};
}

TempDir::TempDir(std::string_view tag)
{
    mPath = fs::temp_directory_path() /
            ("rtlab-gpu-test-" + std::to_string(::getpid()) + "-" +
             std::to_string(gTempCounter.fetch_add(1)) + "-" + std::string(tag));
    fs::remove_all(mPath);
    fs::create_directories(mPath);
}

TempDir::~TempDir()
{
    std::error_code ec;
    fs::remove_all(mPath, ec);
}

fs::path TempDir::writeFile(const fs::path& relative, std::string_view text) const
{
    const fs::path path = mPath / relative;
    fs::create_directories(path.parent_path());
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(text.data(), static_cast<std::streamsize>(text.size()));
    if (!out)
        throw std::runtime_error("cannot write " + path.string());
    return path;
}

ScopedEnv::ScopedEnv(std::string name, std::optional<std::string> value) : mName(std::move(name))
{
    if (const char* old = std::getenv(mName.c_str()))
        mOld = old;
    if (value)
        ::setenv(mName.c_str(), value->c_str(), 1);
    else
        ::unsetenv(mName.c_str());
}

ScopedEnv::~ScopedEnv()
{
    if (mOld)
        ::setenv(mName.c_str(), mOld->c_str(), 1);
    else
        ::unsetenv(mName.c_str());
}

std::string joinMessages(const std::vector<std::string>& messages)
{
    std::string text;
    for (const std::string& m : messages)
        text += m + "\n";
    return text;
}

ContextOptions GpuTest::makeContextOptions() const
{
    ContextOptions options;
    options.enableValidation = true;
    options.echoValidationMessages = false;
    return options;
}

void GpuTest::SetUp()
{
    mCacheDir = std::make_unique<TempDir>("spirv-cache");
    ShaderCompilerOptions compilerOptions;
    compilerOptions.cacheDir = mCacheDir->getPath();
    compilerOptions.includeDirs = {getTestShaderDir()};
    mCompiler.emplace(compilerOptions);

    ContextOptions options = makeContextOptions();
    mLog = std::make_shared<ValidationLog>();
    options.validationLog = mLog;
    mContext.emplace(options);
    ASSERT_TRUE(mContext->isValidationEnabled());
}

void GpuTest::TearDown()
{
    mContext.reset(); // messages about leaked objects arrive while the device is destroyed
    const std::vector<std::string> messages = mLog->getMessages();
    EXPECT_TRUE(messages.empty()) << messages.size() << " validation message(s):\n"
                                  << joinMessages(messages);
    mCompiler.reset();
    mCacheDir.reset();
}

CompiledShader GpuTest::compileTestShader(std::string_view name,
                                          const std::vector<ShaderDefine>& defines) const
{
    return mCompiler->compileFile(getTestShaderDir() / name, defines);
}

ComputePipeline GpuTest::createTestPipeline(std::string_view shaderName,
                                            std::vector<BindingSlot> bindings,
                                            std::uint32_t pushConstantSize,
                                            std::vector<SpecConstant> specConstants,
                                            const std::vector<ShaderDefine>& defines)
{
    ComputePipelineDesc desc;
    desc.name = std::string(shaderName);
    desc.spirv = compileTestShader(shaderName, defines).spirv;
    desc.bindings = std::move(bindings);
    desc.pushConstantSize = pushConstantSize;
    desc.specConstants = std::move(specConstants);
    return getContext().createPipeline(desc);
}

} // namespace rtlab::gpu::test
