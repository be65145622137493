// glTF 2.0 reading: tinygltf parses, this file checks every accessor it uses and flattens the
// default scene's triangle primitives into world space.

#include "scene/mesh_loader.h"

#include "core/error.h"

#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <glm/mat3x3.hpp>
#include <glm/mat4x4.hpp>
#include <tiny_gltf.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <unordered_set>

namespace rtlab::scene::detail {

namespace {

// Images are not used; this keeps tinygltf from decoding them (or failing on their formats).
bool skipImage(tinygltf::Image*, const int, std::string*, std::string*, int, int,
               const unsigned char*, int, void*)
{
    return true;
}

std::string quote(const std::string& s)
{
    return "'" + s + "'";
}

std::string describeMode(int mode)
{
    switch (mode) {
    case TINYGLTF_MODE_POINTS:
        return "POINTS (0)";
    case TINYGLTF_MODE_LINE:
        return "LINES (1)";
    case TINYGLTF_MODE_LINE_LOOP:
        return "LINE_LOOP (2)";
    case TINYGLTF_MODE_LINE_STRIP:
        return "LINE_STRIP (3)";
    case TINYGLTF_MODE_TRIANGLE_STRIP:
        return "TRIANGLE_STRIP (5)";
    case TINYGLTF_MODE_TRIANGLE_FAN:
        return "TRIANGLE_FAN (6)";
    default:
        return std::to_string(mode);
    }
}

std::string trimTrailingNewlines(std::string s)
{
    while (!s.empty() && (s.back() == '\n' || s.back() == '\r' || s.back() == ' '))
        s.pop_back();
    return s;
}

tinygltf::Model parseModel(const std::string& path, const std::string& bytes, bool binary)
{
    if (bytes.size() > std::numeric_limits<unsigned int>::max())
        throw InputError({path}, "glTF file is larger than 4 GiB");
    std::string baseDir = std::filesystem::path(path).parent_path().string();
    if (baseDir.empty())
        baseDir = ".";

    tinygltf::TinyGLTF loader;
    loader.SetImageLoader(&skipImage, nullptr);
    tinygltf::Model model;
    std::string error;
    std::string warning;
    const auto size = static_cast<unsigned int>(bytes.size());
    const bool ok =
        binary ? loader.LoadBinaryFromMemory(&model, &error, &warning,
                                             reinterpret_cast<const unsigned char*>(bytes.data()),
                                             size, baseDir)
               : loader.LoadASCIIFromString(&model, &error, &warning, bytes.data(), size, baseDir);
    if (!ok) {
        error = trimTrailingNewlines(error);
        throw InputError({path}, std::string("cannot parse ") + (binary ? "GLB" : "glTF") +
                                     (error.empty() ? std::string() : ": " + error));
    }
    return model;
}

//! Flattens one parsed model into a RawMesh.
class GltfReader {
public:
    GltfReader(const std::string& path, const tinygltf::Model& model)
        : mPath(path), mModel(model), mMaterialIndex(model.materials.size() + 1, -1)
    {
    }

    RawMesh read()
    {
        for (const std::string& extension : mModel.extensionsRequired)
            if (extension != "KHR_materials_emissive_strength")
                fail("requires extension " + quote(extension) + ", which is not supported");
        std::vector<bool> onPath(mModel.nodes.size(), false);
        for (int root : findRootNodes())
            visitNode(root, glm::dmat4(1.0), onPath);
        return std::move(mRaw);
    }

private:
    [[noreturn]] void fail(const std::string& message) const { throw InputError({mPath}, message); }

    std::vector<int> findRootNodes() const
    {
        if (mModel.scenes.empty()) {
            // No scene: every node that is nobody's child.
            std::vector<bool> isChild(mModel.nodes.size(), false);
            for (const tinygltf::Node& node : mModel.nodes)
                for (int child : node.children)
                    if (child >= 0 && static_cast<std::size_t>(child) < isChild.size())
                        isChild[static_cast<std::size_t>(child)] = true;
            std::vector<int> roots;
            for (std::size_t n = 0; n < isChild.size(); ++n)
                if (!isChild[n])
                    roots.push_back(static_cast<int>(n));
            return roots;
        }
        const int scene = mModel.defaultScene < 0 ? 0 : mModel.defaultScene;
        if (static_cast<std::size_t>(scene) >= mModel.scenes.size())
            fail("default scene " + std::to_string(scene) + " does not exist: the file has " +
                 std::to_string(mModel.scenes.size()) + " scenes");
        return mModel.scenes[static_cast<std::size_t>(scene)].nodes;
    }

    static glm::dmat4 computeLocalTransform(const tinygltf::Node& node)
    {
        if (node.matrix.size() == 16)
            return glm::make_mat4(node.matrix.data()); // column-major, as glTF stores it
        glm::dmat4 m(1.0);
        if (node.translation.size() == 3)
            m[3] = glm::dvec4(node.translation[0], node.translation[1], node.translation[2], 1.0);
        if (node.rotation.size() == 4) {
            // glTF stores (x, y, z, w); glm's constructor takes (w, x, y, z).
            const glm::dquat q(node.rotation[3], node.rotation[0], node.rotation[1],
                               node.rotation[2]);
            m = m * glm::mat4_cast(q);
        }
        if (node.scale.size() == 3)
            m = m * glm::dmat4(glm::dvec4(node.scale[0], 0, 0, 0),
                               glm::dvec4(0, node.scale[1], 0, 0),
                               glm::dvec4(0, 0, node.scale[2], 0), glm::dvec4(0, 0, 0, 1));
        return m;
    }

    void visitNode(int index, const glm::dmat4& parent, std::vector<bool>& onPath)
    {
        if (index < 0 || static_cast<std::size_t>(index) >= mModel.nodes.size())
            fail("node " + std::to_string(index) + " does not exist: the file has " +
                 std::to_string(mModel.nodes.size()) + " nodes");
        const auto n = static_cast<std::size_t>(index);
        if (onPath[n])
            fail("node " + std::to_string(index) + " is its own ancestor");
        const tinygltf::Node& node = mModel.nodes[n];
        const glm::dmat4 world = parent * computeLocalTransform(node);
        if (node.mesh >= 0) {
            if (static_cast<std::size_t>(node.mesh) >= mModel.meshes.size())
                fail("node " + std::to_string(index) + " refers to mesh " +
                     std::to_string(node.mesh) + ", which does not exist");
            const tinygltf::Mesh& mesh = mModel.meshes[static_cast<std::size_t>(node.mesh)];
            for (std::size_t p = 0; p < mesh.primitives.size(); ++p)
                addPrimitive(node.mesh, p, index, world);
        }
        onPath[n] = true;
        for (int child : node.children)
            visitNode(child, world, onPath);
        onPath[n] = false;
    }

    //! A validated view of an accessor's elements.
    struct AccessorView {
        const unsigned char* data = nullptr;
        std::size_t stride = 0;
        std::size_t count = 0;
        int componentType = 0;
    };

    //! Checks accessor `index` (used as `role`) against its buffer view and buffer.
    AccessorView viewAccessor(int index, const std::string& role, int type) const
    {
        const std::string what = "accessor " + std::to_string(index) + " (" + role + ")";
        if (index < 0 || static_cast<std::size_t>(index) >= mModel.accessors.size())
            fail(what + " does not exist: the file has " + std::to_string(mModel.accessors.size()) +
                 " accessors");
        const tinygltf::Accessor& accessor = mModel.accessors[static_cast<std::size_t>(index)];
        if (accessor.sparse.isSparse)
            fail(what + " is sparse, which is not supported");
        if (accessor.type != type)
            fail(what + " has type " + std::to_string(accessor.type) + ", expected " +
                 (type == TINYGLTF_TYPE_VEC3 ? "VEC3" : "SCALAR"));
        if (accessor.bufferView < 0 ||
            static_cast<std::size_t>(accessor.bufferView) >= mModel.bufferViews.size())
            fail(what + " has no valid bufferView (" + std::to_string(accessor.bufferView) + ")");
        const tinygltf::BufferView& view =
            mModel.bufferViews[static_cast<std::size_t>(accessor.bufferView)];
        if (view.buffer < 0 || static_cast<std::size_t>(view.buffer) >= mModel.buffers.size())
            fail("bufferView " + std::to_string(accessor.bufferView) + " of " + what +
                 " refers to buffer " + std::to_string(view.buffer) + ", which does not exist");
        const tinygltf::Buffer& buffer = mModel.buffers[static_cast<std::size_t>(view.buffer)];

        const int componentSize =
            tinygltf::GetComponentSizeInBytes(static_cast<std::uint32_t>(accessor.componentType));
        const int components =
            tinygltf::GetNumComponentsInType(static_cast<std::uint32_t>(accessor.type));
        if (componentSize <= 0 || components <= 0)
            fail(what + " has an invalid componentType " + std::to_string(accessor.componentType));
        const std::size_t elementSize = static_cast<std::size_t>(componentSize * components);
        const std::size_t stride = view.byteStride != 0 ? view.byteStride : elementSize;
        if (stride < elementSize)
            fail("bufferView " + std::to_string(accessor.bufferView) + " of " + what +
                 " has byteStride " + std::to_string(stride) + ", less than the element size " +
                 std::to_string(elementSize));
        if (view.byteOffset > buffer.data.size() ||
            view.byteLength > buffer.data.size() - view.byteOffset)
            fail("bufferView " + std::to_string(accessor.bufferView) + " of " + what + " (bytes " +
                 std::to_string(view.byteOffset) + " + " + std::to_string(view.byteLength) +
                 ") does not fit in buffer " + std::to_string(view.buffer) + " of " +
                 std::to_string(buffer.data.size()) + " bytes");
        if (accessor.count > 0) {
            const std::size_t available = view.byteLength;
            const bool fits =
                accessor.byteOffset <= available &&
                elementSize <= available - accessor.byteOffset &&
                accessor.count - 1 <= (available - accessor.byteOffset - elementSize) / stride;
            if (!fits)
                fail(what + " (" + std::to_string(accessor.count) + " elements from byte " +
                     std::to_string(accessor.byteOffset) + ", stride " + std::to_string(stride) +
                     ") does not fit in bufferView " + std::to_string(accessor.bufferView) +
                     " of " + std::to_string(view.byteLength) + " bytes");
        }
        return {buffer.data.data() + view.byteOffset + accessor.byteOffset, stride, accessor.count,
                accessor.componentType};
    }

    //! Reads a float VEC3 accessor; `element` names one entry ("vertex", "normal") in errors.
    std::vector<glm::vec3> readVec3(int index, const std::string& role,
                                    const std::string& element) const
    {
        const AccessorView view = viewAccessor(index, role, TINYGLTF_TYPE_VEC3);
        if (view.componentType != TINYGLTF_COMPONENT_TYPE_FLOAT)
            fail("accessor " + std::to_string(index) + " (" + role + ") has componentType " +
                 std::to_string(view.componentType) + "; only FLOAT (5126) is supported");
        std::vector<glm::vec3> values(view.count);
        for (std::size_t i = 0; i < view.count; ++i) {
            std::memcpy(&values[i], view.data + i * view.stride, sizeof(glm::vec3));
            for (int c = 0; c < 3; ++c)
                if (!std::isfinite(values[i][c]))
                    fail(element + " " + std::to_string(i) + " of accessor " +
                         std::to_string(index) + " (" + role + ") has a non-finite coordinate (" +
                         std::to_string(values[i][c]) + ")");
        }
        return values;
    }

    std::vector<std::uint32_t> readIndices(int index, const std::string& role,
                                           std::size_t vertexCount) const
    {
        const AccessorView view = viewAccessor(index, role, TINYGLTF_TYPE_SCALAR);
        std::vector<std::uint32_t> values(view.count);
        for (std::size_t i = 0; i < view.count; ++i) {
            const unsigned char* p = view.data + i * view.stride;
            switch (view.componentType) {
            case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
                values[i] = *p;
                break;
            case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
                std::uint16_t v;
                std::memcpy(&v, p, sizeof v);
                values[i] = v;
                break;
            }
            case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
                std::memcpy(&values[i], p, 4);
                break;
            default:
                fail("accessor " + std::to_string(index) + " (" + role + ") has componentType " +
                     std::to_string(view.componentType) +
                     "; indices must be UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT");
            }
            if (values[i] >= vertexCount)
                fail("index " + std::to_string(i) + " of accessor " + std::to_string(index) + " (" +
                     role + ") is " + std::to_string(values[i]) + ", out of range: POSITION has " +
                     std::to_string(vertexCount) + " vertices");
        }
        return values;
    }

    std::uint32_t findMaterial(int material)
    {
        if (material >= static_cast<int>(mModel.materials.size()))
            fail("material " + std::to_string(material) + " does not exist: the file has " +
                 std::to_string(mModel.materials.size()) + " materials");
        const std::size_t slot = material < 0 ? 0 : static_cast<std::size_t>(material) + 1;
        if (mMaterialIndex[slot] >= 0)
            return static_cast<std::uint32_t>(mMaterialIndex[slot]);

        RawMaterial raw; // no material: 0.8 grey, no emission
        if (material >= 0) {
            const tinygltf::Material& m = mModel.materials[static_cast<std::size_t>(material)];
            const std::string label = "material " + std::to_string(material);
            raw.name = m.name.empty() ? label : m.name;
            if (!mMaterialNames.insert(raw.name).second)
                raw.name += " (" + label + ")";
            const std::vector<double>& base = m.pbrMetallicRoughness.baseColorFactor;
            if (base.size() >= 3)
                raw.albedo = glm::vec3(base[0], base[1], base[2]);
            double strength = 1.0;
            const auto ext = m.extensions.find("KHR_materials_emissive_strength");
            if (ext != m.extensions.end() && ext->second.Has("emissiveStrength") &&
                ext->second.Get("emissiveStrength").IsNumber())
                strength = ext->second.Get("emissiveStrength").GetNumberAsDouble();
            if (m.emissiveFactor.size() == 3)
                raw.emission = glm::vec3(
                    glm::dvec3(m.emissiveFactor[0], m.emissiveFactor[1], m.emissiveFactor[2]) *
                    strength);
            for (int c = 0; c < 3; ++c)
                if (!std::isfinite(raw.albedo[c]) || !std::isfinite(raw.emission[c]))
                    fail(label + " " + quote(m.name) + " has a non-finite colour");
        }
        mMaterialIndex[slot] = static_cast<std::int64_t>(mRaw.materials.size());
        mRaw.materials.push_back(std::move(raw));
        return static_cast<std::uint32_t>(mRaw.materials.size() - 1);
    }

    void addPrimitive(int meshIndex, std::size_t p, int nodeIndex, const glm::dmat4& world)
    {
        const tinygltf::Mesh& mesh = mModel.meshes[static_cast<std::size_t>(meshIndex)];
        const tinygltf::Primitive& primitive = mesh.primitives[p];
        const std::string where =
            (mesh.name.empty() ? "mesh " + std::to_string(meshIndex) : "mesh " + quote(mesh.name)) +
            " primitive " + std::to_string(p);
        if (primitive.mode != -1 && primitive.mode != TINYGLTF_MODE_TRIANGLES)
            fail(where + " has mode " + describeMode(primitive.mode) +
                 "; only TRIANGLES (4) is supported");

        const auto positionIt = primitive.attributes.find("POSITION");
        if (positionIt == primitive.attributes.end())
            fail(where + " has no POSITION attribute");
        const std::vector<glm::vec3> positions =
            readVec3(positionIt->second, "POSITION of " + where, "vertex");
        std::vector<glm::vec3> normals;
        const auto normalIt = primitive.attributes.find("NORMAL");
        if (normalIt != primitive.attributes.end()) {
            normals = readVec3(normalIt->second, "NORMAL of " + where, "normal");
            if (normals.size() != positions.size())
                fail("accessor " + std::to_string(normalIt->second) + " (NORMAL of " + where +
                     ") has " + std::to_string(normals.size()) + " normals but POSITION has " +
                     std::to_string(positions.size()) + " vertices");
        }

        std::vector<std::uint32_t> indices;
        if (primitive.indices >= 0) {
            indices = readIndices(primitive.indices, "indices of " + where, positions.size());
            if (indices.size() % 3 != 0)
                fail("accessor " + std::to_string(primitive.indices) + " (indices of " + where +
                     ") has " + std::to_string(indices.size()) + " indices, not a multiple of 3");
        } else {
            if (positions.size() % 3 != 0)
                fail(where + " has no indices and " + std::to_string(positions.size()) +
                     " vertices, not a multiple of 3");
            indices.resize(positions.size());
            for (std::size_t i = 0; i < indices.size(); ++i)
                indices[i] = static_cast<std::uint32_t>(i);
        }

        if (mRaw.positions.size() + positions.size() > std::numeric_limits<std::uint32_t>::max())
            fail("too many vertices");
        const auto base = static_cast<std::uint32_t>(mRaw.positions.size());
        const auto normalBase = static_cast<std::int64_t>(mRaw.normals.size());
        for (std::size_t i = 0; i < positions.size(); ++i) {
            const glm::dvec4 q = world * glm::dvec4(glm::dvec3(positions[i]), 1.0);
            const glm::vec3 p3(q);
            if (!std::isfinite(p3.x) || !std::isfinite(p3.y) || !std::isfinite(p3.z))
                fail("vertex " + std::to_string(i) + " of accessor " +
                     std::to_string(positionIt->second) + " (POSITION of " + where +
                     ") is not finite after the transform of node " + std::to_string(nodeIndex));
            mRaw.positions.push_back(p3);
        }
        const glm::dmat3 linear(world);
        const double det = glm::determinant(linear);
        const bool hasNormals = !normals.empty() && det != 0.0 && std::isfinite(det);
        if (hasNormals) {
            const glm::dmat3 normalMatrix = glm::transpose(glm::inverse(linear));
            for (const glm::vec3& n : normals) {
                const glm::vec3 t(normalMatrix * glm::dvec3(n));
                const bool finite = std::isfinite(t.x) && std::isfinite(t.y) && std::isfinite(t.z);
                mRaw.normals.push_back(finite ? t : glm::vec3(0.0f));
            }
        }

        const std::uint32_t material = findMaterial(primitive.material);
        // A mirroring transform turns counter-clockwise triangles clockwise: swap them back.
        const bool flip = det < 0.0;
        for (std::size_t t = 0; t + 2 < indices.size(); t += 3) {
            for (int c : {0, flip ? 2 : 1, flip ? 1 : 2}) {
                const std::uint32_t i = indices[t + static_cast<std::size_t>(c)];
                mRaw.cornerPosition.push_back(base + i);
                mRaw.cornerNormal.push_back(hasNormals ? normalBase + i : -1);
            }
            mRaw.triangleMaterial.push_back(material);
        }
    }

    const std::string& mPath;
    const tinygltf::Model& mModel;
    RawMesh mRaw;
    std::vector<std::int64_t> mMaterialIndex; //!< per glTF material + 1 (slot 0: none)
    std::unordered_set<std::string> mMaterialNames;
};

} // namespace

RawMesh readGltf(const std::string& path, const std::string& bytes, bool binary)
{
    const tinygltf::Model model = parseModel(path, bytes, binary);
    RawMesh raw = GltfReader(path, model).read();
    raw.formatFlatReason = "no NORMAL"; // glTF 2.0, "Meshes": flat normals without NORMAL
    return raw;
}

} // namespace rtlab::scene::detail
