#include "scene/mesh_loader.h"

#include "core/error.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <bit>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <unordered_map>

namespace rtlab::scene {

namespace detail {

std::string readWholeFile(const std::string& path)
{
    std::error_code ec;
    const auto status = std::filesystem::status(path, ec);
    if (!std::filesystem::exists(status))
        throw InputError({path}, "file not found");
    if (std::filesystem::is_directory(status))
        throw InputError({path}, "is a directory, not a file");
    std::ifstream in(path, std::ios::binary);
    if (!in)
        throw InputError({path}, std::string("cannot open file: ") + std::strerror(errno));
    std::ostringstream contents;
    contents << in.rdbuf();
    if (in.bad())
        throw InputError({path}, std::string("cannot read file: ") + std::strerror(errno));
    return std::move(contents).str();
}

namespace {

glm::dvec3 computeTriangleCross(const RawMesh& raw, std::size_t triangle)
{
    const glm::dvec3 a(raw.positions[raw.cornerPosition[3 * triangle + 0]]);
    const glm::dvec3 b(raw.positions[raw.cornerPosition[3 * triangle + 1]]);
    const glm::dvec3 c(raw.positions[raw.cornerPosition[3 * triangle + 2]]);
    return glm::cross(b - a, c - a);
}

bool isDegenerate(const RawMesh& raw, std::size_t triangle)
{
    const std::uint32_t* corner = &raw.cornerPosition[3 * triangle];
    if (corner[0] == corner[1] || corner[1] == corner[2] || corner[0] == corner[2])
        return true;
    return computeTriangleCross(raw, triangle) == glm::dvec3(0.0);
}

// Whether some edge, with vertices identified by their coordinates, has more than two triangles.
bool hasNonManifoldEdge(const std::vector<glm::vec3>& positions,
                        const std::vector<std::uint32_t>& indices)
{
    struct Key {
        std::uint32_t bits[3];
        bool operator==(const Key& o) const
        {
            return bits[0] == o.bits[0] && bits[1] == o.bits[1] && bits[2] == o.bits[2];
        }
    };
    struct KeyHash {
        std::size_t operator()(const Key& k) const
        {
            std::uint64_t h = 1469598103934665603ull;
            for (std::uint32_t b : k.bits)
                h = (h ^ b) * 1099511628211ull;
            return static_cast<std::size_t>(h);
        }
    };
    std::unordered_map<Key, std::uint32_t, KeyHash> pointIds;
    pointIds.reserve(positions.size());
    std::vector<std::uint32_t> pointOf(positions.size());
    for (std::size_t v = 0; v < positions.size(); ++v) {
        // Bit patterns with -0 folded into +0: equal keys are equal points.
        Key key;
        for (int i = 0; i < 3; ++i)
            key.bits[i] = std::bit_cast<std::uint32_t>(positions[v][i] + 0.0f);
        pointOf[v] =
            pointIds.try_emplace(key, static_cast<std::uint32_t>(pointIds.size())).first->second;
    }

    std::vector<std::uint64_t> edges;
    edges.reserve(indices.size());
    for (std::size_t t = 0; t + 2 < indices.size(); t += 3)
        for (int e = 0; e < 3; ++e) {
            std::uint64_t a = pointOf[indices[t + e]];
            std::uint64_t b = pointOf[indices[t + (e + 1) % 3]];
            if (a > b)
                std::swap(a, b);
            edges.push_back(a << 32 | b);
        }
    std::sort(edges.begin(), edges.end());
    for (std::size_t i = 0; i + 2 < edges.size(); ++i)
        if (edges[i] == edges[i + 2])
            return true;
    return false;
}

} // namespace

LoadedMesh finishMesh(const std::string& path, const RawMesh& raw)
{
    const std::size_t rawTriangles = raw.cornerPosition.size() / 3;
    LoadedMesh mesh;

    // Triangles that survive, and per position the area-weighted normal sum (|cross| = 2 area)
    // and the first adjacent triangle's normal as a fallback where the sum cancels out.
    std::vector<std::size_t> kept;
    kept.reserve(rawTriangles);
    std::vector<glm::dvec3> normalSum(raw.positions.size(), glm::dvec3(0.0));
    std::vector<glm::dvec3> firstNormal(raw.positions.size(), glm::dvec3(0.0));
    for (std::size_t t = 0; t < rawTriangles; ++t) {
        if (isDegenerate(raw, t)) {
            ++mesh.degenerateTrianglesDropped;
            continue;
        }
        kept.push_back(t);
        const glm::dvec3 cross = computeTriangleCross(raw, t);
        for (int c = 0; c < 3; ++c) {
            const std::uint32_t p = raw.cornerPosition[3 * t + c];
            normalSum[p] += cross;
            if (firstNormal[p] == glm::dvec3(0.0))
                firstNormal[p] = glm::normalize(cross);
        }
    }
    if (kept.empty()) {
        std::string message = "contains no triangles";
        const std::size_t dropped = mesh.degenerateTrianglesDropped;
        if (dropped == 1)
            message += " (its only triangle is degenerate: a repeated vertex or zero area)";
        else if (dropped > 1)
            message += " (all " + std::to_string(dropped) +
                       " triangles are degenerate: a repeated vertex or zero area)";
        throw InputError({path}, message);
    }

    // Vertices: the distinct (position, normal) pairs of the kept corners, in file order.
    auto makeKey = [&](std::size_t corner) {
        return static_cast<std::uint64_t>(raw.cornerPosition[corner]) << 32 |
               static_cast<std::uint64_t>(raw.cornerNormal[corner] + 1);
    };
    std::vector<std::uint64_t> vertexKeys;
    vertexKeys.reserve(3 * kept.size());
    for (std::size_t t : kept)
        for (int c = 0; c < 3; ++c)
            vertexKeys.push_back(makeKey(3 * t + c));
    std::sort(vertexKeys.begin(), vertexKeys.end());
    vertexKeys.erase(std::unique(vertexKeys.begin(), vertexKeys.end()), vertexKeys.end());

    mesh.positions.reserve(vertexKeys.size());
    mesh.normals.reserve(vertexKeys.size());
    for (std::uint64_t key : vertexKeys) {
        const auto p = static_cast<std::uint32_t>(key >> 32);
        const auto n = static_cast<std::int64_t>(key & 0xffffffffull) - 1;
        mesh.positions.push_back(raw.positions[p]);
        glm::dvec3 normal(0.0);
        if (n >= 0)
            normal = glm::dvec3(raw.normals[static_cast<std::size_t>(n)]);
        if (normal == glm::dvec3(0.0))
            normal = normalSum[p] != glm::dvec3(0.0) ? normalSum[p] : firstNormal[p];
        mesh.normals.push_back(glm::vec3(glm::normalize(normal)));
    }

    // Triangles and materials.
    std::vector<std::int64_t> outputMaterial(raw.materials.size(), -1);
    mesh.indices.reserve(3 * kept.size());
    mesh.triangleMaterial.reserve(kept.size());
    for (std::size_t t : kept) {
        for (int c = 0; c < 3; ++c) {
            const auto it =
                std::lower_bound(vertexKeys.begin(), vertexKeys.end(), makeKey(3 * t + c));
            mesh.indices.push_back(static_cast<std::uint32_t>(it - vertexKeys.begin()));
        }
        const std::uint32_t m = raw.triangleMaterial[t];
        const RawMaterial& material = raw.materials[m];
        if (outputMaterial[m] < 0) {
            outputMaterial[m] = static_cast<std::int64_t>(mesh.materialNames.size());
            mesh.materialNames.push_back(material.name);
            mesh.materialAlbedo.push_back(material.albedo);
            mesh.materialEmission.push_back(material.emission);
        }
        mesh.triangleMaterial.push_back(material.name);
    }

    mesh.nonManifold = hasNonManifoldEdge(mesh.positions, mesh.indices);
    mesh.warnings = raw.warnings;
    return mesh;
}

} // namespace detail

LoadedMesh loadMesh(const std::string& path, const MeshLoadOptions& options)
{
    std::string extension = std::filesystem::path(path).extension().string();
    std::transform(extension.begin(), extension.end(), extension.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    if (extension != ".obj" && extension != ".gltf" && extension != ".glb")
        throw InputError({path},
                         (extension.empty() ? std::string("mesh file has no extension")
                                            : "unsupported mesh format '" + extension + "'") +
                             ": supported are .obj, .gltf and .glb");

    const std::string contents = detail::readWholeFile(path);
    const detail::RawMesh raw = extension == ".obj"
                                    ? detail::readObj(path, contents, options)
                                    : detail::readGltf(path, contents, extension == ".glb");
    return detail::finishMesh(path, raw);
}

} // namespace rtlab::scene
