#include "scene/mesh_loader.h"

#include "core/error.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <array>
#include <bit>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <tuple>
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

LoadedMesh finishMesh(const std::string& path, const RawMesh& raw, const NormalMode& mode)
{
    const std::size_t rawTriangles = raw.cornerPosition.size() / 3;
    LoadedMesh mesh;

    // Triangles that survive, their area-weighted normals (|cross| = 2 area) and unit normals.
    std::vector<std::size_t> kept;
    kept.reserve(rawTriangles);
    for (std::size_t t = 0; t < rawTriangles; ++t) {
        if (isDegenerate(raw, t)) {
            ++mesh.degenerateTrianglesDropped;
            continue;
        }
        kept.push_back(t);
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
    std::vector<glm::dvec3> cross(kept.size()), unit(kept.size());
    for (std::size_t i = 0; i < kept.size(); ++i) {
        cross[i] = computeTriangleCross(raw, kept[i]);
        unit[i] = glm::normalize(cross[i]);
    }
    // The kept triangles around each position (compressed rows).
    std::vector<std::size_t> rowStart(raw.positions.size() + 1, 0);
    for (std::size_t i = 0; i < kept.size(); ++i)
        for (int c = 0; c < 3; ++c)
            ++rowStart[raw.cornerPosition[3 * kept[i] + c] + 1];
    for (std::size_t p = 0; p < raw.positions.size(); ++p)
        rowStart[p + 1] += rowStart[p];
    std::vector<std::size_t> around(rowStart.back()), fill(rowStart.begin(), rowStart.end() - 1);
    for (std::size_t i = 0; i < kept.size(); ++i)
        for (int c = 0; c < 3; ++c)
            around[fill[raw.cornerPosition[3 * kept[i] + c]]++] = i;

    // Each corner's normal (see mesh_loader.h, "Normals"), then the vertices: the distinct
    // (position, normal) pairs, ordered by position.
    using Kind = NormalMode::Kind;
    const bool groups = mode.kind == Kind::FromFile && !raw.triangleSmoothing.empty();
    const double creaseCos = mode.kind == Kind::CreaseAngle
                                 ? std::cos(mode.creaseAngleDegrees * 3.14159265358979323846 / 180.0)
                                 : 0.0;
    std::vector<std::string> sources;
    const auto note = [&](const std::string& s) {
        if (std::find(sources.begin(), sources.end(), s) == sources.end())
            sources.push_back(s);
    };
    struct Corner {
        std::uint32_t position;
        std::array<float, 3> normal;
        bool operator<(const Corner& o) const
        {
            return std::tie(position, normal) < std::tie(o.position, o.normal);
        }
        bool operator==(const Corner& o) const
        {
            return position == o.position && normal == o.normal;
        }
    };
    std::vector<Corner> corners(3 * kept.size());
    for (std::size_t i = 0; i < kept.size(); ++i) {
        const std::size_t t = kept[i];
        for (int c = 0; c < 3; ++c) {
            const std::uint32_t p = raw.cornerPosition[3 * t + c];
            const std::int64_t fileNormal = raw.cornerNormal[3 * t + c];
            glm::dvec3 n(0.0);
            if (mode.kind == Kind::FromFile && fileNormal >= 0) {
                n = glm::dvec3(raw.normals[static_cast<std::size_t>(fileNormal)]);
                if (n != glm::dvec3(0.0))
                    note("file (vn)");
            }
            if (n == glm::dvec3(0.0)) {
                const std::uint32_t group = groups ? raw.triangleSmoothing[t] : 0u;
                const bool smooth = mode.kind == Kind::Smooth || mode.kind == Kind::CreaseAngle ||
                                    (mode.kind == Kind::FromFile && group != 0u);
                if (smooth) {
                    for (std::size_t a = rowStart[p]; a < rowStart[p + 1]; ++a) {
                        const std::size_t j = around[a];
                        const bool joins =
                            mode.kind == Kind::Smooth ||
                            (mode.kind == Kind::CreaseAngle
                                 ? glm::dot(unit[i], unit[j]) >= creaseCos - 1e-12
                                 : raw.triangleSmoothing[kept[j]] == group);
                        if (joins)
                            n += cross[j];
                    }
                    note(mode.kind == Kind::FromFile ? "smoothing groups" : mode.describe());
                } else {
                    note(mode.kind == Kind::FromFile ? "flat (" + raw.formatFlatReason + ")"
                                                     : mode.describe());
                }
                // Flat, or a sum that cancels (faces wound against each other): the face's own.
                if (!(glm::dot(n, n) > 0.0))
                    n = cross[i];
            }
            const glm::vec3 u(glm::normalize(n));
            corners[3 * i + std::size_t(c)] = {p, {u.x, u.y, u.z}};
        }
    }
    std::vector<Corner> vertices = corners;
    std::sort(vertices.begin(), vertices.end());
    vertices.erase(std::unique(vertices.begin(), vertices.end()), vertices.end());
    mesh.positions.reserve(vertices.size());
    mesh.normals.reserve(vertices.size());
    for (const Corner& v : vertices) {
        mesh.positions.push_back(raw.positions[v.position]);
        mesh.normals.push_back(glm::vec3(v.normal[0], v.normal[1], v.normal[2]));
    }
    for (std::size_t s = 0; s < sources.size(); ++s)
        mesh.normalsSource += (s ? " and " : "") + sources[s];

    // Triangles and materials.
    std::vector<std::int64_t> outputMaterial(raw.materials.size(), -1);
    mesh.indices.reserve(3 * kept.size());
    mesh.triangleMaterial.reserve(kept.size());
    for (std::size_t i = 0; i < kept.size(); ++i) {
        const std::size_t t = kept[i];
        for (int c = 0; c < 3; ++c) {
            const auto it = std::lower_bound(vertices.begin(), vertices.end(),
                                             corners[3 * i + std::size_t(c)]);
            mesh.indices.push_back(static_cast<std::uint32_t>(it - vertices.begin()));
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
    return detail::finishMesh(path, raw, options.normals);
}

std::string NormalMode::describe() const
{
    switch (kind) {
    case Kind::FromFile:
        return "from file";
    case Kind::Flat:
        return "flat";
    case Kind::Smooth:
        return "smooth";
    case Kind::CreaseAngle: {
        std::ostringstream s;
        s << "crease angle " << creaseAngleDegrees;
        return s.str();
    }
    }
    return "?";
}

} // namespace rtlab::scene
