#pragma once
// What the sparse voxel_gi structures share (the octree `svo`, the 64-ary tree
// `adaptive_voxel_tree_cones`): their leaves, how the leaves are lit, and how a level of the
// structure is sampled and filtered. A structure differs from the others only in how it finds the
// element at a cell of a level (its topology) and in how many children a node has per axis.
//
//  * Leaves: the surface voxels of the family's voxelization (the "voxel fragments" of Crassin
//    et al. 2011), voxelized block by block over the lattice, plus layers of solid voxels just
//    inside closed surfaces that mirror the light of the surface leaf they were reached from.
//  * Payload per element and face: rgb = the light a pixel gathers, a = occupancy
//    ("gathered"), and the light fields of cone_tracing.h during injection (premultiplied).
//  * Filtering: a parent's face is the mean over the columns of its children along the face's
//    axis, each column composited front to back as the face's viewer sees it (anisotropic
//    voxels, Crassin 2011 section 5 and Crassin's thesis section 5.1).
//  * Sampling: trilinear between the 8 element centres around the point at a level; an element
//    that does not exist is empty (its filtered value is exactly 0).

#include "families/voxel_gi/cone_tracing.h"
#include "families/voxel_gi/pixel_cones.h"
#include "families/voxel_gi/voxelize.h"
#include "scene/render_scene.h"

#include <glm/common.hpp>
#include <glm/gtc/constants.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

namespace rtlab::voxelgi {

//! One leaf of a sparse structure: a surface voxel, or a voxel of the layers just inside a closed
//! surface.
struct SurfaceLeaf {
    glm::ivec3 coord{0};                       //!< leaf lattice coordinates
    std::array<glm::vec4, kFaceCount> faces{}; //!< albedo, occupancy per face
    std::array<glm::vec3, kFaceCount> emission{};
    glm::vec3 normal{0.0f};
    //! -1 for a surface voxel; for a voxel of the layers just inside a closed surface, the index
    //! of the surface leaf whose light it mirrors (the one it was reached from; it is not lit
    //! itself).
    std::int32_t inwardOf = -1;
};

struct LeafLattice {
    glm::dvec3 origin{0.0}; //!< world position of the lattice's min corner
    double leafSize = 1.0;  //!< world units
    glm::ivec3 cells{1};    //!< leaves per axis
    int supersampling = 4;  //!< voxelization rays per leaf column and axis, per side
    int chunk = 32;         //!< leaves per side of the blocks voxelized independently (power of two)
    //! Layers of solid voxels kept inside closed surfaces (1..8): the solid voxels within this
    //! many face steps of a surface voxel, each mirroring the surface leaf it was reached from.
    int innerLayers = 1;
};

//! The leaves of `geometry` in the lattice: the blocks of chunk^3 leaves a triangle meets (exact
//! test, listCellsMeetingTriangles) voxelized each on its own (voxelizeTriangles), their surface
//! voxels, and the solid voxels within innerLayers face steps of one (inwardOf set; blocks that
//! no triangle meets are not voxelized, so a layer thicker than a block stops there). A block
//! voxelizes every triangle its columns meet along some axis, however far, so that its solid
//! spans close between their entry and exit faces. Leaves outside `cells` are left out. `who` names the caller in errors. Throws rtlab::Error for a bad lattice or more
//! than 2^31 surface leaves.
std::vector<SurfaceLeaf> voxelizeSurfaceLeaves(const scene::RenderScene& geometry, const LeafLattice& lattice,
                                               const std::string& who);

//! Makes the leaves isotropic (the octree paper's leaves hold one opacity; directions appear in
//! the filtered levels): a leaf is as opaque from every side as its best-covered axis, and a face
//! its axis rays did not see takes the coverage-weighted mean colour and emission of the others.
//! The axis rays of the voxelization see a wall only along its normal, and a cone crossing it
//! obliquely would blend in the wall's zero coverage along the other axes and see through. Inner
//! leaves take the emission of their surface leaf. Throws rtlab::Error (naming `who`) where an
//! inner leaf mirrors a leaf that is not a surface leaf.
void makeLeavesIsotropic(std::vector<SurfaceLeaf>& leaves, const std::string& who);

//! The payload of a sparse structure, per element and face.
struct SparsePayload {
    //! [element * 6 + face]: rgb = the light a pixel gathers (the reflected fields up to the
    //! bounces, premultiplied), a = occupancy.
    std::vector<glm::vec4> gathered;
    //! [element * 6 + face], premultiplied: the light fields, during injection only (the
    //! emission field is kept after it when some leaf emits).
    std::array<std::vector<glm::vec3>, kFieldCount> fields;

    std::size_t getElementCount() const { return gathered.size() / kFaceCount; }
};

//! The face a cone travelling along `d` on `axis` sees: +axis travel sees the -axis face.
inline int getFaceSeen(int axis, double d)
{
    return 2 * axis + (d > 0.0 ? 1 : 0);
}

//! Filters one parent element's 6 faces from its K^3 children (`child[x + K (y + K z)]`, an
//! element index or -1 for none): per face, each of the K^2 columns along the face's axis
//! composited front to back as the face's viewer sees it (value_front + (1 - alpha_front)
//! value_back, premultiplied), the columns averaged. `get(element * 6 + face)` is the value
//! filtered (the occupancy, or a light field); `alpha` the children's final occupancies.
template <int K, class Get>
void filterParentFaces(const std::int64_t* child, std::size_t parent, const std::vector<glm::vec4>& alpha,
                       const Get& get)
{
    for (int f = 0; f < kFaceCount; ++f) {
        const int axis = f / 2;
        // The viewer of an odd face (-axis) looks along +axis: front = the low children.
        const bool fromLow = (f % 2) == 1;
        const int u = (axis + 1) % 3, v = (axis + 2) % 3;
        auto sum = get(0) * 0.0f;
        for (int j = 0; j < K; ++j)
            for (int i = 0; i < K; ++i) {
                float transmit = 1.0f;
                auto column = get(0) * 0.0f;
                for (int s = 0; s < K; ++s) {
                    int c[3];
                    c[axis] = fromLow ? s : K - 1 - s;
                    c[u] = i;
                    c[v] = j;
                    const std::int64_t e = child[c[0] + K * (c[1] + K * c[2])];
                    if (e < 0)
                        continue; // empty: lets everything through
                    const std::size_t g = std::size_t(e) * kFaceCount + std::size_t(f);
                    column += transmit * get(g);
                    transmit *= 1.0f - alpha[g].a;
                }
                sum += column;
            }
        get(parent * kFaceCount + std::size_t(f)) = (1.0f / float(K * K)) * sum;
    }
}

//! Adds `weight` times the trilinear sample at world point p of the level whose cells are
//! `cellSize` wide (lattice min corner `origin`) to `out`, for a cone travelling along `dir`
//! (each axis's face seen, weighted by dir_axis^2). `find(ivec3 cell) -> int64` is the
//! structure's lookup at that level (-1: none, empty). Gathered: the gathered light (into
//! out.light[kDirect]); else the light fields.
template <bool Gathered, class Find>
void sampleSparseLevel(const Find& find, const glm::dvec3& origin, double cellSize, const SparsePayload& payload,
                       const glm::dvec3& p, const glm::dvec3& dir, float weight, ConeSample& out)
{
    const glm::dvec3 c = (p - origin) / cellSize - 0.5;
    const glm::dvec3 f = glm::floor(c);
    const glm::ivec3 i0(f);
    const glm::dvec3 t = c - f;
    int faceSeen[3];
    float axisWeight[3];
    for (int a = 0; a < 3; ++a) {
        faceSeen[a] = getFaceSeen(a, dir[a]);
        axisWeight[a] = float(dir[a] * dir[a]);
    }
    for (int corner = 0; corner < 8; ++corner) {
        const int dx = corner & 1, dy = (corner >> 1) & 1, dz = (corner >> 2) & 1;
        const double w = (dx ? t.x : 1.0 - t.x) * (dy ? t.y : 1.0 - t.y) * (dz ? t.z : 1.0 - t.z);
        if (w == 0.0)
            continue;
        const std::int64_t e = find(i0 + glm::ivec3(dx, dy, dz));
        if (e < 0)
            continue; // an empty region
        const float fw = float(w) * weight;
        for (int a = 0; a < 3; ++a) {
            const float aw = fw * axisWeight[a];
            if (aw == 0.0f)
                continue;
            const std::size_t g = std::size_t(e) * kFaceCount + std::size_t(faceSeen[a]);
            const glm::vec4& v = payload.gathered[g];
            out.alpha += aw * v.a;
            if (out.wantsDepth)
                out.depth += aw * computeOpticalDepth(v.a);
            if constexpr (Gathered) {
                out.light[kDirect] += aw * glm::vec3(v);
                // The emitters the pixels' cones meet (kept only when some leaf emits).
                if (!payload.fields[kEmission].empty())
                    out.light[kEmission] += aw * payload.fields[kEmission][g];
            } else {
                for (int field = 0; field < kFieldCount; ++field)
                    out.light[std::size_t(field)] += aw * payload.fields[std::size_t(field)][g];
            }
        }
    }
}

struct LeafLightSettings {
    glm::dvec3 origin{0.0}; //!< the leaf lattice's min corner
    double leafSize = 1.0;
    int bounces = 2;        //!< 1..3
    double startOffset = 4.0; //!< leaves
    double stepScale = 0.5;
};

//! Light injection into a sparse structure whose occupancy (payload.gathered's a) is filtered:
//! emission, then `bounces` passes (direct, then each bounce from the previous field), each the
//! family's 16-cone gather from every surface leaf through `sampler` (the light fields), written
//! per face as albedo / pi * E at the leaf's occupancy, mirrored into the inner leaves, then
//! filtered up the structure by `filterField(field)`; finally gathered = the sum of the
//! reflected fields (the filter is linear in the light for given occupancies, so the sum of the
//! filtered fields is the filtered sum) and the fields released. leafElement[i] is leaf i's
//! element.
template <class Sampler, class FilterField>
void injectLeafLight(const scene::RenderScene& geometry, const ConeSet& cones, const std::vector<SurfaceLeaf>& leaves,
                     const std::vector<std::uint32_t>& leafElement, const LeafLightSettings& s,
                     SparsePayload& payload, const Sampler& sampler, const FilterField& filterField)
{
    const std::size_t faces = payload.gathered.size();
    for (auto& field : payload.fields)
        field.assign(faces, glm::vec3(0.0f));
    const auto at = [&](std::size_t leaf, int f) { return std::size_t(leafElement[leaf]) * kFaceCount + std::size_t(f); };
    for (std::size_t i = 0; i < leaves.size(); ++i)
        for (int f = 0; f < kFaceCount; ++f)
            payload.fields[kEmission][at(i, f)] = payload.gathered[at(i, f)].a * leaves[i].emission[std::size_t(f)];
    filterField(int(kEmission));

    InjectionLights lights;
    lights.pointLights = &geometry.pointLights;
    lights.hasSky = geometry.sky.emits();
    if (lights.hasSky)
        lights.skyPerCone = computeSkyPerCone(geometry.sky, cones);
    InjectionSettings settings;
    settings.startOffset = s.startOffset;
    settings.march.stepScale = s.stepScale;
    // Three passes (the family's three_pass schedule): direct, then each bounce from the field
    // the previous pass wrote, filtered up before the next pass reads it.
    std::vector<std::array<glm::vec3, kFaceCount>> written(leaves.size());
    for (int pass = 0; pass < s.bounces; ++pass) {
        const int field = kDirect + pass;
        tbb::parallel_for(std::size_t(0), leaves.size(), [&](std::size_t i) {
            const SurfaceLeaf& l = leaves[i];
            if (l.inwardOf >= 0)
                return; // mirrors its surface leaf, below
            InjectionVoxel v;
            v.centre = s.origin + (glm::dvec3(l.coord) + 0.5) * s.leafSize;
            v.normal = l.normal;
            v.voxelSize = s.leafSize;
            v.faces = l.faces.data();
            const FaceIrradiance e = gatherVoxelIrradiance(sampler, v, cones, lights, settings);
            for (int f = 0; f < kFaceCount; ++f) {
                const float a = payload.gathered[at(i, f)].a;
                written[i][std::size_t(f)] = glm::vec3(l.faces[std::size_t(f)]) * (a / glm::pi<float>()) *
                                             e.e[std::size_t(field)][std::size_t(f)];
            }
        });
        for (std::size_t i = 0; i < leaves.size(); ++i) {
            // An inner leaf takes its surface leaf's radiance per face, at its own occupancy.
            const std::int32_t from = leaves[i].inwardOf;
            for (int f = 0; f < kFaceCount; ++f) {
                glm::vec3 light = written[i][std::size_t(f)];
                if (from >= 0) {
                    const float as = payload.gathered[at(std::size_t(from), f)].a;
                    const float a = payload.gathered[at(i, f)].a;
                    light = as > 0.0f ? written[std::size_t(from)][std::size_t(f)] * (a / as) : glm::vec3(0.0f);
                }
                payload.fields[std::size_t(field)][at(i, f)] = light;
            }
        }
        filterField(field);
    }
    tbb::parallel_for(std::size_t(0), faces, [&](std::size_t g) {
        glm::vec3 sum(0.0f);
        for (int field = kDirect; field < kDirect + s.bounces; ++field)
            sum += payload.fields[std::size_t(field)][g];
        payload.gathered[g] = glm::vec4(sum, payload.gathered[g].a);
    });
    // The reflected fields are released; the emission stays when some leaf emits, for the
    // pixels' cones that meet the emitters (pixel_cones.h computeConeSkyRadiance).
    const bool emits = std::any_of(payload.fields[kEmission].begin(), payload.fields[kEmission].end(),
                                   [](const glm::vec3& e) { return e != glm::vec3(0.0f); });
    for (int field = 0; field < kFieldCount; ++field)
        if (field != kEmission || !emits)
            std::vector<glm::vec3>().swap(payload.fields[std::size_t(field)]);
}

//! cone_tracing.h Samplers of a sparse structure S (its light fields during injection, its
//! gathered light for the pixels): S has sampleFields and sampleGathered(p, diameter, dir, out).
template <class S>
struct SparseFieldSampler {
    const S* structure;
    bool sample(const glm::dvec3& p, double d, int, const glm::dvec3& dir, ConeSample& out) const
    {
        return structure->sampleFields(p, d, dir, out);
    }
};
template <class S>
struct SparseGatheredSampler {
    const S* structure;
    bool sample(const glm::dvec3& p, double d, int, const glm::dvec3& dir, ConeSample& out) const
    {
        return structure->sampleGathered(p, d, dir, out);
    }
};

//! The 16 cones of every pixel through a sparse structure S (S::preparePixel says where they
//! start): pixel_cones.h traceGBufferCones. Returns the mean number of steps per cone.
template <class S>
double traceSparsePixelCones(const S& structure, const scene::GBuffer& gbuffer, std::vector<glm::vec3>& out,
                             const ConeSkyOutput* sky = nullptr)
{
    const auto prepare = [&](const scene::GBuffer& g, int x, int y, glm::dvec3& origin, glm::dvec3& n,
                             ConeMarchSettings& march) { return structure.preparePixel(g, x, y, origin, n, march); };
    return traceGBufferCones(gbuffer, structure.getCones(), prepare, SparseGatheredSampler<S>{&structure}, out,
                             sky);
}

//! `rays` zero-aperture rays per pixel through a sparse structure S: pixel_cones.h traceGBufferRays
//! (with `sky`: the sky and emitters they see).
template <class S>
void traceSparsePixelRays(const S& structure, const scene::GBuffer& gbuffer, int rays, Image<glm::vec3>& out,
                          const scene::Sky* sky = nullptr)
{
    const auto prepare = [&](const scene::GBuffer& g, int x, int y, glm::dvec3& origin, glm::dvec3& n,
                             ConeMarchSettings& march) { return structure.preparePixel(g, x, y, origin, n, march); };
    traceGBufferRays(gbuffer, rays, prepare, SparseGatheredSampler<S>{&structure}, out, sky);
}

} // namespace rtlab::voxelgi
