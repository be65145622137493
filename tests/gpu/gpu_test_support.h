#pragma once
// Shared helpers of the gpu tests: a fixture with validation that fails the test on any
// validation message, scoped environment variables, temporary directories and test shaders.

#include <gtest/gtest.h>

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "gpu/context.h"
#include "gpu/shader_compiler.h"

namespace rtlab::gpu::test {

//! tests/gpu/shaders ($RTLAB_SOURCE_DIR/tests/gpu/shaders when that variable is set).
std::filesystem::path getTestShaderDir();

//! A fresh, empty directory under the system temp dir, removed by the destructor.
class TempDir {
public:
    explicit TempDir(std::string_view tag);
    ~TempDir();
    TempDir(const TempDir&) = delete;
    TempDir& operator=(const TempDir&) = delete;
    const std::filesystem::path& getPath() const { return mPath; }

    //! Writes `text` to getPath() / relative (creating directories) and returns the full path.
    std::filesystem::path writeFile(const std::filesystem::path& relative,
                                    std::string_view text) const;

private:
    std::filesystem::path mPath;
};

//! Sets (or with nullopt, unsets) an environment variable and restores it on destruction.
class ScopedEnv {
public:
    ScopedEnv(std::string name, std::optional<std::string> value);
    ~ScopedEnv();
    ScopedEnv(const ScopedEnv&) = delete;
    ScopedEnv& operator=(const ScopedEnv&) = delete;

private:
    std::string mName;
    std::optional<std::string> mOld;
};

//! All messages of a log, one per line, for failure output.
std::string joinMessages(const std::vector<std::string>& messages);

//! Creates a Context with validation for each test and fails the test if the validation layer
//! reported anything, including while the device is destroyed at the end of the test.
class GpuTest : public ::testing::Test {
public:
    Context& getContext() { return *mContext; }
    const std::shared_ptr<ValidationLog>& getValidationLog() const { return mLog; }
    //! A compiler with the test shader dir as include dir and a private cache dir.
    const ShaderCompiler& getCompiler() const { return *mCompiler; }
    //! Compiles tests/gpu/shaders/<name>.
    CompiledShader compileTestShader(std::string_view name,
                                     const std::vector<ShaderDefine>& defines = {}) const;
    //! Compiles a test shader and creates a pipeline from it.
    ComputePipeline createTestPipeline(std::string_view shaderName,
                                       std::vector<BindingSlot> bindings,
                                       std::uint32_t pushConstantSize = 0,
                                       std::vector<SpecConstant> specConstants = {},
                                       const std::vector<ShaderDefine>& defines = {});

protected:
    void SetUp() override;
    void TearDown() override;

    //! Options of the test's Context (validation on, messages collected, not echoed).
    virtual ContextOptions makeContextOptions() const;

private:
    std::unique_ptr<TempDir> mCacheDir;
    std::optional<ShaderCompiler> mCompiler;
    std::shared_ptr<ValidationLog> mLog;
    std::optional<Context> mContext;
};

} // namespace rtlab::gpu::test
