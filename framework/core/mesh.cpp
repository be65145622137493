#include "core/mesh.h"

#include "core/error.h"

#include <cstdio>
#include <memory>

namespace rtlab {

void writeObj(const TriangleMesh& mesh, const std::string& path)
{
    std::unique_ptr<std::FILE, int (*)(std::FILE*)> f(std::fopen(path.c_str(), "w"), &std::fclose);
    if (!f)
        throw Error(path + ": cannot open for writing");
    for (const auto& p : mesh.positions)
        std::fprintf(f.get(), "v %.9g %.9g %.9g\n", p.x, p.y, p.z);
    const bool normals = mesh.normals.size() == mesh.positions.size() && !mesh.normals.empty();
    if (normals)
        for (const auto& n : mesh.normals)
            std::fprintf(f.get(), "vn %.6g %.6g %.6g\n", n.x, n.y, n.z);
    for (std::size_t i = 0; i + 2 < mesh.indices.size(); i += 3) {
        const auto a = mesh.indices[i] + 1, b = mesh.indices[i + 1] + 1, c = mesh.indices[i + 2] + 1;
        if (normals)
            std::fprintf(f.get(), "f %u//%u %u//%u %u//%u\n", a, a, b, b, c, c);
        else
            std::fprintf(f.get(), "f %u %u %u\n", a, b, c);
    }
    if (std::ferror(f.get()))
        throw Error(path + ": write failed");
}

} // namespace rtlab
