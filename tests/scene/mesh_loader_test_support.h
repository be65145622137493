#pragma once
// What the mesh loader's tests share: a temporary folder of files, the InputError a path must
// raise, a vector comparison and a unit quad's vertices.

#include "scene/mesh_loader.h"

#include "core/error.h"

#include <glm/vec3.hpp>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

namespace rtlab::scene::test {

namespace fs = std::filesystem;

class TempDir {
public:
    explicit TempDir(const std::string& name)
        : mPath(fs::temp_directory_path() / ("rtlab_mesh_loader_test_" + name))
    {
        fs::remove_all(mPath);
        fs::create_directories(mPath);
    }
    ~TempDir() { fs::remove_all(mPath); }
    TempDir(const TempDir&) = delete;
    TempDir& operator=(const TempDir&) = delete;

    //! Writes `contents` to `name` inside the directory and returns its path.
    std::string write(const std::string& name, const std::string& contents) const
    {
        const fs::path file = mPath / name;
        std::ofstream(file, std::ios::binary) << contents;
        return file.string();
    }
    std::string path(const std::string& name) const { return (mPath / name).string(); }

private:
    fs::path mPath;
};

//! Loads `path` expecting an InputError and returns it.
inline rtlab::InputError expectInputError(const std::string& path)
{
    try {
        loadMesh(path);
    } catch (const rtlab::InputError& e) {
        return e;
    }
    ADD_FAILURE() << "no InputError for " << path;
    return rtlab::InputError({path}, "");
}

inline void expectVec3Near(const glm::vec3& actual, const glm::vec3& expected, float tolerance = 1e-6f)
{
    EXPECT_NEAR(actual.x, expected.x, tolerance);
    EXPECT_NEAR(actual.y, expected.y, tolerance);
    EXPECT_NEAR(actual.z, expected.z, tolerance);
}

inline constexpr char kQuadObj[] = "v 0 0 0\n"
                        "v 1 0 0\n"
                        "v 1 1 0\n"
                        "v 0 1 0\n";

} // namespace rtlab::scene::test
