#pragma once
// The voxel texture cascade of the Tomorrow Children (shared/seeds/000_3da000e866ebc485.txt,
// "Voxel Texture Cascade", "Data Layout", "Cascade Update", "Cascade selection"): N levels of R^3
// anisotropic voxels centred on the camera, each doubling the extent of the one inside it.
// Per level the volumetric G-buffer (voxelize.h) and the light buffers per face (direct, first
// and second bounce, cone_tracing.h's fields); optionally the pre-combined direction buffers
// (per voxel and per cone direction the occupancy and the light a pixel gathers, the three faces
// blended once instead of at every step of every cone: "Pre-Combine Anisotropic Voxels").
//
// Level selection at a point p for a footprint d: the coarsest of log2(d / v0) and the level
// whose region holds p, blended smoothly (the talk's concentric spheres: from half of a level's
// radius the start level moves toward the next one), with the two nearest levels interpolated.

#include "core/image.h"
#include "families/voxel_gi/cone_tracing.h"
#include "scene/gbuffer.h"
#include "families/voxel_gi/voxelize.h"

#include <glm/vec4.hpp>

#include <array>
#include <functional>
#include <string>
#include <vector>

namespace rtlab::voxelgi {

struct CascadeSettings {
    int levels = 6;
    int resolution = 32;   //!< even
    double voxelSize = 0.0; //!< level 0, world units (> 0)
    int supersampling = 4;
    bool solid = true;
    int bounces = 2;                    //!< 1..3 reflections gathered at the pixel
    bool onePass = false;               //!< the talk's staggered one-pass update
    bool oneLevelPerFrame = true;       //!< level i every 2^(i+1) frames
    double coneHalfAngleDegrees = 29.0;
    double startOffset = 1.0; //!< voxels
    //! Voxels (of the pixel's start level; of their own level for far cones) along a pixel cone
    //! from which its voxels shadow the sky (cone_tracing.h ConeMarchSettings::skyStartDistance).
    double skyStart = 4.0;
    bool skyOpticalDepth = false; //!< cone_tracing.h ConeMarchSettings::skyOpticalDepth
    double stepScale = 0.5;
    bool precombine = true;
    //! Split near/far cones ("Split Cone Trace"): the pixel traces its cones up to farStart
    //! voxels of its start level and takes the rest from far cones traced once per voxel centre
    //! of that level and interpolated trilinearly. 0: every cone traced whole per pixel.
    double farStart = 0.0;
    //! Add the talk's extrapolated extra bounce (cone_tracing.h extrapolateBounce) of the last
    //! two gathered bounces to the light the pixels gather (bounces >= 2): B + 1 reflections.
    bool extrapolate = false;
    //! The talk's "3D noise offset" on the start-level blend (pixel cones only): the blend's
    //! radius is offset by levelNoise * (2 n - 1) of the level's radius, n a smooth 3D noise of
    //! the point (computeValueNoise on the level-0 voxel lattice). 0: no noise.
    double levelNoise = 0.0;
};

//! Smooth 3D value noise in [0, 1): the hashes of the 8 corners of lattice cell `cell`
//! interpolated trilinearly at `frac` in [0, 1]^3 (hash: pcg3d, Jarzynski and Olano, "Hash
//! Functions for GPU Rendering", JCGT 2020). The same bits as shaders/cascade_gather.comp.
float computeValueNoise(const glm::ivec3& cell, const glm::vec3& frac);

class CascadeVolume {
public:
    struct Level {
        VoxelRegion region;
        VoxelGrid grid;
        std::vector<float> alpha;                                //!< [voxel * 6 + face]
        std::array<std::vector<glm::vec3>, kFieldCount> light;   //!< [voxel * 6 + face], premultiplied
        //! [cone * voxels + voxel]: alpha, premultiplied gathered light. Cone-major, so that a
        //! trilinear sample's x neighbours share a cache line and a GPU warp marching one cone
        //! from neighbouring pixels reads neighbouring entries.
        std::vector<glm::vec4> combined;
        std::string geometryKey;         //!< of the voxelized geometry
        bool voxelized = false;
        //! Some voxel emits: the pixels' cones then sample light[kEmission] too (their sky and
        //! emitters, pixel_cones.h ConeSkyOutput).
        bool emits = false;
        std::uint64_t voxelStamp = 0; //!< when it was last voxelized (CascadeVolume's counter)
        std::uint64_t lightStamp = 0; //!< when its light buffers last changed
        //! Changes whenever the light buffers change, between the passes of one update too (what
        //! a copy of them on the GPU is checked against).
        std::uint64_t lightRevision = 0;
        std::uint64_t litStamp = 0;   //!< what it was lit against: every stamp up to this one
        int litCount = 0;             //!< one-pass updates since its inputs last changed
        glm::dvec3 centre{0.0};
        //! Bounds of the triangles that appeared or disappeared since it was voxelized (min > max
        //! when none): what a re-voxelization of only the changed region must cover.
        glm::dvec3 changedMin{1e300}, changedMax{-1e300};
        //! Solid voxels and the nearest surface voxel, whose light they mirror.
        std::vector<std::pair<std::uint32_t, std::uint32_t>> inward;
        //! The far cones of the voxel centres (settings.farStart > 0), traced when a pixel first
        //! needs them: farSlot[voxel] is ~0u or the slot s of its 16 cones' gathered radiance
        //! beyond farStart voxels, far[s * 16 + cone]. Valid while no level they sample changed
        //! since farStamp.
        std::vector<std::uint32_t> farSlot;
        std::vector<glm::vec3> far;
        //! The same far cones' sky and emitters (cone_tracing.h computeConeSkyRadiance, against
        //! the sky of the volume's farSky key), [s * 16 + cone]; empty when they were traced
        //! on Vulkan (which keeps no transmittance).
        std::vector<glm::vec3> farSky;
        std::uint64_t farStamp = 0;
    };

    explicit CascadeVolume(CascadeSettings settings);

    const CascadeSettings& getSettings() const { return mSettings; }
    const ConeSet& getCones() const { return mCones; }
    int getLevelCount() const { return int(mLevels.size()); }
    const Level& getLevel(int i) const { return mLevels[std::size_t(i)]; }

    //! Region of level `i` for a camera at `camera` (snapped to 2 voxels of the level, so that
    //! the levels stay nested on voxel boundaries).
    VoxelRegion computeRegion(int level, const glm::dvec3& camera) const;
    //! Levels due at `frame` (every level on the first update or with oneLevelPerFrame off).
    std::vector<int> getDueLevels(int frame) const;

    //! What voxelizes a region (voxelize.h voxelizeTriangles, or on Vulkan voxelize_gpu.h).
    using Voxelizer = std::function<VoxelGrid(const scene::RenderScene& geometry, const VoxelRegion& region,
                                              const VoxelizeOptions& options)>;
    //! Re-voxelizes the due levels whose region or geometry changed (all when `force`), with
    //! `voxelizer` when given, else voxelizeTriangles. Returns a description of what it did (""
    //! when nothing).
    //! Tells the volume that the geometry of key `toKey` differs from that of `fromKey` only by
    //! triangles inside [lo, hi] (lo > hi: none), so that the next voxelize() of `toKey` need not
    //! compare the triangles to find it. Ignored (false) unless `fromKey` is the geometry the
    //! volume saw last.
    bool noteGeometryChange(const std::string& fromKey, const std::string& toKey,
                            const glm::dvec3& lo, const glm::dvec3& hi);
    std::string voxelize(const scene::RenderScene& geometry, const std::string& geometryKey,
                         const glm::dvec3& camera, int frame, bool force, const Voxelizer& voxelizer = {});
    //! The irradiance per face of the surface voxels of a level (in the order of its
    //! grid.surfaceVoxels) from the volume's current light buffers: what gatherVoxelIrradiance
    //! gives over sampleFields with getInjectionSettings(), computed elsewhere (on Vulkan:
    //! cascade_inject_gpu.h).
    using IrradianceGather =
        std::function<void(int level, const InjectionLights& lights, std::vector<FaceIrradiance>& out)>;
    //! Updates the light buffers of the due levels that are stale. `lightsKey` changes with the
    //! lights and sky. The surface voxels' cones are traced in C++ unless `gather` is given.
    //! Returns what it did ("" when nothing).
    std::string injectLight(const scene::RenderScene& geometry, const std::string& lightsKey,
                            int frame, bool force, const IrradianceGather& gather = {});
    //! The march and offsets light injection uses.
    InjectionSettings getInjectionSettings() const;
    //! The radiance each of the 16 cones gathers at every pixel of `gbuffer`, [pixel * 16 +
    //! cone]; 0 for cones below the surface and for pixels without a surface or outside the
    //! cascade. With `sky`, also the sky and emitters each cone sees (cone_tracing.h
    //! ConeSkyOutput); with split near/far cones the far cones keep theirs beside their light.
    void gatherCones(const scene::GBuffer& gbuffer, std::vector<glm::vec3>& out,
                     const ConeSkyOutput* sky = nullptr);
    //! The same light gathered along `rays` cosine-distributed rays per pixel (zero aperture:
    //! every sample at the finest level holding it), E = pi * mean radiance; the directions are
    //! a stratified grid turned per pixel, so the result is deterministic.
    //! With `sky`: the sky and emitters the rays see (pixel_cones.h traceGBufferRays).
    void gatherRays(const scene::GBuffer& gbuffer, int rays, Image<glm::vec3>& out,
                    const scene::Sky* sky = nullptr) const;
    //! Far cones to trace: (level, voxel) of each centre; out gets the 16 cones' radiance of
    //! each, [centre * 16 + cone] (on Vulkan: CascadeGatherGpu::traceFarCones), and `sky`, when
    //! not null, their sky and emitters (computeConeSkyRadiance) the same way, or nothing (the
    //! far cones then keep no sky).
    using FarConeTracer = std::function<void(const std::vector<std::pair<int, std::uint32_t>>& centres,
                                             std::vector<glm::vec3>& out, std::vector<glm::vec3>* sky)>;
    //! Whether the following far cones also carry the cones' sky (the sky per cone), or not
    //! (null); another sky drops every far cone (their sky is stale). gatherCones with a
    //! ConeSkyOutput calls it; a Vulkan gather calls it before prepareFarCones.
    void setConeSky(const std::array<glm::vec3, kConeCount>* skyPerCone);
    //! With settings.farStart > 0: drops the far cones of levels whose sampled levels changed and
    //! traces those the pixels of `gbuffer` need that are not traced yet, in C++ or with
    //! `tracer` (gatherCones calls it; the Vulkan gather needs it called first).
    void prepareFarCones(const scene::GBuffer& gbuffer, const FarConeTracer& tracer = {});
    //! The world position of voxel `voxel`'s centre in level `level`.
    glm::dvec3 getVoxelCentre(int level, std::uint32_t voxel) const;
    //! The lowest level the far cones of level `i` sample (their footprint at farStart, or the
    //! point's own level, whichever is coarser; never finer than this).
    int getFarDependency(int i) const;
    //! Indirect irradiance at every pixel of `gbuffer`: gatherCones combined per pixel
    //! (upsample.h combineCones), cones weighted by `coneVisibility` when given.
    //! Per pixel, the floor of its cones' start level (the level noise included), 255 where the
    //! pixel has no surface or lies outside every level: the discontinuity metric's level map.
    void computeStartLevels(const scene::GBuffer& gbuffer, Image<std::uint8_t>& levels) const;
    void gather(const scene::GBuffer& gbuffer, const std::vector<Image<float>>* coneVisibility,
                Image<glm::vec3>& out);

    //! Sampler of the light fields (injection) and of the gathered light (pixels): see
    //! cone_tracing.h.
    bool sampleFields(const glm::dvec3& p, double diameter, int cone, const glm::dvec3& dir,
                      ConeSample& out) const;
    bool sampleGathered(const glm::dvec3& p, double diameter, int cone, const glm::dvec3& dir,
                        ConeSample& out) const;

    //! marchCone's samplers over this volume: the light fields (injection) and the gathered
    //! light (pixels; `perCone` false blends the faces along each direction, for rays).
    struct FieldSampler {
        const CascadeVolume* volume;
        bool sample(const glm::dvec3& p, double d, int cone, const glm::dvec3& dir,
                    ConeSample& out) const
        {
            return volume->sampleFields(p, d, cone, dir, out);
        }
    };
    struct GatheredSampler {
        const CascadeVolume* volume;
        bool perCone = true;
        bool sample(const glm::dvec3& p, double d, int cone, const glm::dvec3& dir,
                    ConeSample& out) const
        {
            return volume->sampleGathered(p, d, perCone ? cone : -1, dir, out);
        }
    };

    std::size_t getPayloadBytes() const;
    std::size_t getTopologyBytes() const;
    //! Counts of the last calls, for the row.
    struct Counters {
        int levelsVoxelized = 0;
        //! Of the last voxelize(): the voxels of the changed (dug) boxes it voxelized again, and
        //! the wall time of those calls (the voxelizer's, with the paste into the level).
        std::size_t changedVoxels = 0;
        double changedMs = 0.0;
        int levelsLit = 0;
        std::size_t surfaceVoxelsLit = 0;
        double meanStepsPerCone = 0.0;
        std::size_t farConesTraced = 0; //!< by the last gather (the far cones it had to trace)
        std::size_t farVoxelsCached = 0; //!< voxel centres whose far cones are held after it
        double farConesMs = 0.0;   //!< wall time of the last gather's far cones
        double pixelConesMs = 0.0; //!< ... of its pixel cones (whole, or the near parts)
        //! Wall time of the last injectLight's surface-voxel cones (C++, or the IrradianceGather
        //! given, uploads and read-back included), every pass.
        double injectConesMs = 0.0;
    };
    const Counters& getCounters() const { return mCounters; }

private:
    // Where a pixel's cones start (origin, normal, start distance and step); false when it has no
    // surface or lies outside every level.
    bool preparePixel(const scene::GBuffer& gbuffer, int x, int y, glm::dvec3& origin,
                      glm::dvec3& n, ConeMarchSettings& march, double* startLevel = nullptr) const;
    // The pixel's start levels: l0 = floor(start), l1 = l0 + 1 when it is voxelized and the
    // start blends toward it (frac > 0), else -1.
    struct StartLevels {
        int l0 = 0, l1 = -1;
        double frac = 0.0;
    };
    StartLevels getStartLevels(double start) const;
    // gatherCones with split near/far cones (settings.farStart > 0).
    void gatherConesSplit(const scene::GBuffer& gbuffer, std::vector<glm::vec3>& out,
                          const ConeSkyOutput* sky);
    // Drops the far cones of every level whose sampled levels changed since they were traced.
    void invalidateFarCones();
    // The trilinear neighbourhood of a point in a level's far cones, found once for its 16 cones.
    struct FarNeighbourhood {
        std::array<std::size_t, 8> voxels;
        std::array<double, 8> weights;
    };
    FarNeighbourhood findFar(const Level& level, const glm::dvec3& p) const;
    // Trilinear far radiance of cone `cone` in `level` (its traced voxel centres) over `around`.
    //! The far cones' light at `around` (or, with `sky`, their sky and emitters).
    glm::vec3 sampleFar(const Level& level, const FarNeighbourhood& around, int cone,
                        bool sky = false) const;
    // The 8 voxels (of the trilinear neighbourhood of p in `region`) and their weights.
    static void getTrilinear(const VoxelRegion& region, const glm::dvec3& p,
                             std::array<std::size_t, 8>& voxels, std::array<double, 8>& weights);
    // The level to sample at p for footprint d, continuous; < 0 when p is outside every level.
    // With `noisy` (pixel cones), the blend between levels carries settings.levelNoise.
    double selectLevel(const glm::dvec3& p, double diameter, bool noisy = false) const;
    template <bool Gathered>
    bool sampleAt(const glm::dvec3& p, double diameter, int cone, const glm::dvec3& dir,
                  ConeSample& out) const;
    void sampleLevel(const Level& level, const glm::dvec3& p, int cone, const glm::dvec3& dir,
                     bool gathered, float weight, ConeSample& out) const;
    void lightLevel(int level, const scene::RenderScene& geometry, const IrradianceGather& gather);
    void propagateInward(Level& level);
    void updateCombined(Level& level);
    // The reflected light a pixel gathers from face f: bounces 1..B (and the extrapolated one).
    glm::vec3 getGatheredLight(const Level& level, std::size_t f) const;

    CascadeSettings mSettings;
    ConeSet mCones;
    //! The sky per cone the far cones' farSky was computed with (all far cones are dropped when
    //! a gather asks for another).
    std::array<glm::vec3, kConeCount> mFarSkyPerCone{};
    bool mTraceSky = false; //!< the current gather wants the cones' sky (far cones keep theirs)
    std::vector<Level> mLevels;
    bool isStale(int level) const;
    // Records the triangles that appeared or disappeared since the last geometry (their bounds,
    // into every level's changed box).
    void trackGeometryChange(const scene::RenderScene& geometry, const std::string& geometryKey);
    struct TriangleKey {
        std::uint64_t hash = 0;
        glm::vec3 lo{0.0f}, hi{0.0f};
        bool operator<(const TriangleKey& o) const { return hash < o.hash; }
    };
    std::vector<TriangleKey> mTriangles; //!< of the last geometry seen, sorted by hash
    std::string mTrianglesKey;
    //! mTriangles is not that of mTrianglesKey (a noted change replaced the comparison): the
    //! next comparison has nothing to compare with.
    bool mTrianglesStale = false;
    std::uint64_t mStamp = 0;
    std::uint64_t mRevision = 0; //!< Level::lightRevision's counter
    std::string mLightsKey;
    int mFirstFrame = -1;
    Counters mCounters;
};

} // namespace rtlab::voxelgi
