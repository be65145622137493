#include "cascade_gather_gpu.h"
#include "gpu/shader_compiler.h"

#include "core/error.h"

#include <glm/vec4.hpp>

#include <algorithm>
#include <cstring>

namespace rtlab::voxelgi {

namespace {

struct GatherConstants {
    glm::ivec4 size{0};  // width, height, levels, resolution
    glm::vec4 march{0};  // level-0 voxel size, tan(half-angle), start offset, step scale
    glm::ivec4 flags{0}; // visibility given, max steps
    glm::ivec4 anchorCell{0}; // the anchor in level-0 voxels
    glm::vec4 noise{0.0f};    // x: level noise (of a level's radius)
    glm::vec4 sky{0.0f};      // makeConeSkyConstants (the sky start in voxels)
};
static_assert(sizeof(GatherConstants) == 96, "must match cascade_gather.comp");

} // namespace

glm::dvec3 getGpuAnchor(const CascadeVolume& volume)
{
    for (int i = volume.getLevelCount() - 1; i >= 0; --i)
        if (volume.getLevel(i).voxelized)
            return volume.getLevel(i).centre;
    return glm::dvec3(0.0);
}

std::vector<GpuCascadeLevel> describeGpuLevels(const CascadeVolume& volume, const glm::dvec3& anchor,
                                               bool needCombined)
{
    std::vector<GpuCascadeLevel> levels(static_cast<std::size_t>(volume.getLevelCount()));
    for (int i = 0; i < volume.getLevelCount(); ++i) {
        const auto& level = volume.getLevel(i);
        if (!level.voxelized || (needCombined && level.combined.size() != level.region.getVoxelCount() * kConeCount))
            continue;
        const VoxelRegion& r = level.region;
        levels[std::size_t(i)].origin = glm::vec4(glm::vec3(r.origin - anchor), float(r.voxelSize));
        levels[std::size_t(i)].centre = glm::vec4(glm::vec3(level.centre - anchor),
                                                  float((0.5 * r.resolution - 1.0) * r.voxelSize));
    }
    return levels;
}

std::filesystem::path CascadeGatherGpu::getShaderDir()
{
    return gpu::findShaderDir("techniques/voxel_gi/cascades/shaders",
                              std::filesystem::path(RTLAB_TECHNIQUE_DIR) / "shaders");
}

glm::dvec3 CascadeGatherGpu::prepare(gpu::Context& context, const CascadeVolume& volume)
{
    const CascadeSettings& settings = volume.getSettings();
    if (!settings.precombine)
        throw Error("cascades: the Vulkan gather reads the pre-combined direction buffers "
                    "(precombine: true)");
    if (!mDispatch.isReadyFor(context)) {
        const auto sky = mSkyPerCone;
        *this = CascadeGatherGpu();
        mSkyPerCone = sky;
        mDispatch.create(context, getShaderDir() / "cascade_gather.comp", kDispatchLabel,
                         sizeof(GatherConstants), volume.getCones(), 5, true);
        mFarListPlaceholder = mDispatch.makeBuffer(64, "cascades.far_list_placeholder");
        mFaces = mDispatch.makeBuffer(16, "cascades.faces");
        mFarSky = mDispatch.makeBuffer(16, "cascades.far_sky");
        mResidentFarSky = mDispatch.makeBuffer(16, "cascades.far_sky_resident");
    }
    const int n = volume.getLevelCount();
    const int R = settings.resolution;
    const std::size_t levelVoxels = std::size_t(R) * std::size_t(R) * std::size_t(R);
    const std::size_t levelBytes = levelVoxels * kConeCount * sizeof(glm::vec4);
    if (mCombinedLevelVoxels != levelVoxels || mCombinedLevelCount != n) {
        mCombined = mDispatch.makeBuffer(levelBytes * std::size_t(n), "cascades.combined");
        mCombinedLevelVoxels = levelVoxels;
        mCombinedLevelCount = n;
        mUploadedStamps.assign(std::size_t(n), 0);
    }
    // Everything relative to the coarsest voxelized level's centre (float precision far away).
    const glm::dvec3 anchor = getGpuAnchor(volume);
    const std::vector<GpuCascadeLevel> levels = describeGpuLevels(volume, anchor, true);
    for (int i = 0; i < n; ++i) {
        const auto& level = volume.getLevel(i);
        if (levels[std::size_t(i)].centre.w < 0.0f)
            continue;
        const std::uint64_t stamp = std::max(level.voxelStamp, level.lightStamp);
        if (mUploadedStamps[std::size_t(i)] != stamp) {
            mCombined.upload(level.combined.data(), levelBytes, levelBytes * std::size_t(i));
            mUploadedStamps[std::size_t(i)] = stamp;
            mLastUploadBytes += levelBytes;
        }
    }
    if (mSkyPerCone) {
        // The faces the sky's march reads (occupancy, emission), per level as the light.
        mLastUploadBytes += mDispatch.setSkyPerCone(*mSkyPerCone);
        const std::size_t faceBytes = levelVoxels * kFaceCount * sizeof(glm::vec4);
        if (mFaces.getSize() < faceBytes * std::size_t(n)) {
            mFaces = mDispatch.makeBuffer(faceBytes * std::size_t(n), "cascades.faces");
            mUploadedFaceStamps.assign(std::size_t(n), 0);
        }
        mUploadedFaceStamps.resize(std::size_t(n), 0);
        // A level's faces go up where the sky's march reads them: its occupancy for the optical
        // depth, its emission where it emits (in occupancy, a level that does not emit needs
        // none: the pre-combined buffers hold the rest).
        const bool opticalDepth = volume.getSettings().skyOpticalDepth;
        mEmittingLevels = 0;
        for (int i = 0; i < n; ++i) {
            const auto& level = volume.getLevel(i);
            if (levels[std::size_t(i)].centre.w < 0.0f)
                continue;
            if (level.emits)
                mEmittingLevels |= 1u << i;
            const std::uint64_t stamp = std::max(level.voxelStamp, level.lightStamp);
            if (!(opticalDepth || level.emits) || mUploadedFaceStamps[std::size_t(i)] == stamp)
                continue;
            const auto& emission = level.light[kEmission];
            std::vector<glm::vec4> faces(levelVoxels * kFaceCount);
            for (std::size_t f = 0; f < faces.size() && f < level.alpha.size(); ++f)
                faces[f] = glm::vec4(f < emission.size() ? emission[f] : glm::vec3(0.0f), level.alpha[f]);
            mFaces.upload(faces.data(), faceBytes, faceBytes * std::size_t(i));
            mUploadedFaceStamps[std::size_t(i)] = stamp;
            mLastUploadBytes += faceBytes;
        }
    }
    if (!mLevels.isValid() || mLevels.getSize() < levels.size() * sizeof(GpuCascadeLevel))
        mLevels =
            mDispatch.makeBuffer(levels.size() * sizeof(GpuCascadeLevel), "cascades.levels", true);
    mLevels.uploadSpan<GpuCascadeLevel>(levels);
    return anchor;
}

namespace {

GatherConstants makeConstants(const CascadeVolume& volume, const glm::dvec3& anchor, glm::ivec2 size, bool far,
                              bool sky, std::uint32_t emittingLevels)
{
    const CascadeSettings& settings = volume.getSettings();
    GatherConstants constants;
    constants.size = {size.x, size.y, volume.getLevelCount(), settings.resolution};
    constants.march = {float(settings.voxelSize), float(volume.getCones().tanHalfAngle),
                       float(settings.startOffset), float(settings.stepScale)};
    constants.flags = {0, 1024, far ? 1 : 0, 0};
    // The noise lattice is the world's level-0 voxels: the anchor (a level centre, on a lattice
    // of whole level-0 voxels) as integer cells, positions relative to it.
    const glm::dvec3 anchorCells = glm::round(anchor / settings.voxelSize);
    constants.anchorCell = glm::ivec4(glm::ivec3(anchorCells), 0);
    constants.noise = {float(settings.levelNoise), float(settings.farStart), 0.0f, 0.0f};
    constants.sky = makeConeSkyConstants(sky, settings.skyStart, settings.skyOpticalDepth, false);
    constants.sky.w = sky ? float(emittingLevels) : 0.0f; // a bit per level that emits (levels < 24)
    return constants;
}

} // namespace

void CascadeGatherGpu::gatherCones(gpu::Context& context, const CascadeVolume& volume,
                                   const scene::GBuffer& gbuffer, std::vector<glm::vec3>& out)
{
    trace(context, volume, PixelSource{.gbuffer = &gbuffer}, &out);
}

const gpu::Buffer& CascadeGatherGpu::gatherConesOnDevice(gpu::Context& context,
                                                         const CascadeVolume& volume,
                                                         const scene::GBuffer& gbuffer)
{
    trace(context, volume, PixelSource{.gbuffer = &gbuffer}, nullptr);
    return mDispatch.getOutput();
}

const PixelConeDispatch& CascadeGatherGpu::gatherConesResident(gpu::Context& context, const CascadeVolume& volume,
                                                              const PixelSource& pixels)
{
    const CascadeSettings& settings = volume.getSettings();
    mLastFarLevelsDropped = 0;
    if (settings.farStart <= 0.0) {
        trace(context, volume, pixels, nullptr);
        return mDispatch;
    }
    mLastUploadBytes = 0;
    const glm::dvec3 anchor = prepare(context, volume);
    mLastUploadBytes += mDispatch.preparePixels(pixels, anchor);
    const int n = volume.getLevelCount();
    const std::size_t R = std::size_t(settings.resolution);
    const std::size_t levelVoxels = R * R * R;
    if (!mResidentFarState.isValid() || mResidentFarVoxels != levelVoxels * std::size_t(n)) {
        mResidentFarVoxels = levelVoxels * std::size_t(n);
        mResidentFarState = mDispatch.makeBuffer(mResidentFarVoxels * sizeof(std::uint32_t), "cascades.far_state");
        mResidentFarCones =
            mDispatch.makeBuffer(mResidentFarVoxels * kConeCount * sizeof(glm::vec4), "cascades.far_cones_resident");
        mResidentFarList = mDispatch.makeBuffer(32 + mResidentFarVoxels * sizeof(std::uint32_t), "cascades.far_list");
        mResidentFarInputs.assign(std::size_t(n), {});
    }
    // The far cones' sky, when traced: kept with the far cones, all of them dropped when the sky
    // changes or is wanted where they were traced without it.
    if (mSkyPerCone) {
        if (mResidentFarSky.getSize() < mResidentFarVoxels * kConeCount * sizeof(glm::vec4))
            mResidentFarSky =
                mDispatch.makeBuffer(mResidentFarVoxels * kConeCount * sizeof(glm::vec4), "cascades.far_sky_resident");
        if (mResidentFarSkyOf != mSkyPerCone) {
            mResidentFarInputs.assign(std::size_t(n), {});
            mResidentFarSkyOf = mSkyPerCone;
        }
    } else {
        mResidentFarSkyOf.reset(); // far cones traced from now on carry no sky
    }
    // The far cones of level i sample levels getFarDependency(i) and coarser: drop them when one
    // of those changed since (CascadeVolume::invalidateFarCones), or on first use.
    std::vector<std::uint64_t> stamps(static_cast<std::size_t>(n));
    for (int j = 0; j < n; ++j)
        stamps[std::size_t(j)] = std::max(volume.getLevel(j).voxelStamp, volume.getLevel(j).lightStamp);
    // The list's header (its count) every time; the states of the levels whose far cones are
    // dropped.
    std::vector<PixelConeDispatch::Clear> clear = {{2, 0, 32}};
    for (int i = 0; i < n; ++i) {
        std::vector<std::uint64_t> inputs(stamps.begin() + volume.getFarDependency(i), stamps.end());
        if (inputs == mResidentFarInputs[std::size_t(i)])
            continue;
        mResidentFarInputs[std::size_t(i)] = std::move(inputs);
        clear.push_back({0, std::size_t(i) * levelVoxels * sizeof(std::uint32_t), levelVoxels * sizeof(std::uint32_t)});
    }
    mLastFarLevelsDropped = clear.size() - 1;
    const glm::ivec2 size = pixels.getSize();
    mLastTracedSky = mSkyPerCone.has_value();
    GatherConstants gather = makeConstants(volume, anchor, size, false, mLastTracedSky, mEmittingLevels);
    gather.flags.w = 1; // resident far cones
    const auto mode = [&](int z) {
        GatherConstants c = gather;
        c.flags.z = z;
        std::vector<std::byte> b(sizeof(c));
        std::memcpy(b.data(), &c, sizeof(c));
        return b;
    };
    const gpu::GroupCount pixelGroups{gpu::computeGroupCount(std::uint64_t(size.x), 8),
                                      gpu::computeGroupCount(std::uint64_t(size.y), 8), 1};
    // Mark and list (2), count (5), trace the listed voxels' 16 cones (3) and commit them (4),
    // the last two sized by the count on the device.
    const std::vector<PixelConeDispatch::Step> steps = {
        {mode(2), pixelGroups},
        {mode(5), {1, 1, 1}},
        {mode(3), {}, &mResidentFarList, 4},
        {mode(4), {}, &mResidentFarList, 16}};
    mLastGpuMs = mDispatch.runWithSteps(
        mLevels, mCombined, gpu::PushConstants(gather),
        {&mResidentFarState, &mResidentFarCones, &mResidentFarList, &mFaces, &mResidentFarSky}, clear, steps);
    return mDispatch;
}

void CascadeGatherGpu::trace(gpu::Context& context, const CascadeVolume& volume,
                             const PixelSource& pixels, std::vector<glm::vec3>* out)
{
    mLastUploadBytes = 0;
    const glm::dvec3 anchor = prepare(context, volume);
    mLastUploadBytes += mDispatch.preparePixels(pixels, anchor);
    uploadFarCones(volume);
    // The sky where the far cones hold theirs too (CascadeVolume::prepareFarCones keeps it while
    // every far cone was traced with it).
    mLastTracedSky = mSkyPerCone.has_value() && (volume.getSettings().farStart <= 0.0 || mFarSkyUploaded);
    mLastGpuMs = mDispatch.run(
        mLevels, mCombined,
        gpu::PushConstants(makeConstants(volume, anchor, pixels.getSize(), false, mLastTracedSky, mEmittingLevels)),
        out, {&mFarSlots, &mFarCones, &mFarListPlaceholder, &mFaces, &mFarSky});
}

void CascadeGatherGpu::traceFarCones(gpu::Context& context, const CascadeVolume& volume,
                                     const std::vector<std::pair<int, std::uint32_t>>& centres,
                                     std::vector<glm::vec3>& out, std::vector<glm::vec3>* sky)
{
    mLastUploadBytes = 0;
    const glm::dvec3 anchor = prepare(context, volume);
    std::vector<glm::vec4> positions(centres.size()), sizes(centres.size());
    for (std::size_t k = 0; k < centres.size(); ++k) {
        const auto [level, voxel] = centres[k];
        positions[k] = glm::vec4(glm::vec3(volume.getVoxelCentre(level, voxel) - anchor), 1.0f);
        sizes[k] = glm::vec4(0.0f, 0.0f, 0.0f, float(volume.getLevel(level).region.voxelSize));
    }
    mLastUploadBytes += mDispatch.uploadPoints(positions, sizes);
    // The far-cone buffers are not read in this mode; the bindings need buffers.
    if (!mFarSlots.isValid()) {
        mFarSlots = mDispatch.makeBuffer(16, "cascades.far_slots");
        mFarCones = mDispatch.makeBuffer(16, "cascades.far_cones");
    }
    const bool traceSky = sky != nullptr && mSkyPerCone.has_value();
    mLastGpuMs = mDispatch.run(
        mLevels, mCombined,
        gpu::PushConstants(makeConstants(volume, anchor, mDispatch.getPointsSize(), true, traceSky, mEmittingLevels)), &out,
        {&mFarSlots, &mFarCones, &mFarListPlaceholder, &mFaces, &mFarSky}, true);
    if (sky != nullptr) {
        sky->clear();
        if (traceSky) {
            mDispatch.readBackSky(*sky, true);
            sky->resize(out.size());
        }
    }
}

void CascadeGatherGpu::uploadFarCones(const CascadeVolume& volume)
{
    const CascadeSettings& settings = volume.getSettings();
    const int n = volume.getLevelCount();
    const std::size_t levelVoxels = std::size_t(settings.resolution) * std::size_t(settings.resolution) *
                                    std::size_t(settings.resolution);
    if (settings.farStart <= 0.0) {
        // The shader does not read them; the bindings still need buffers.
        if (!mFarSlots.isValid()) {
            mFarSlots = mDispatch.makeBuffer(16, "cascades.far_slots");
            mFarCones = mDispatch.makeBuffer(16, "cascades.far_cones");
        }
        return;
    }
    // Everything again when any level's far cones changed (new slots or invalidated), or their
    // sky came or went.
    std::vector<std::pair<std::uint64_t, std::size_t>> state(static_cast<std::size_t>(n) + 1);
    for (int i = 0; i < n; ++i) {
        const auto& level = volume.getLevel(i);
        if (level.voxelized && level.farSlot.size() != levelVoxels)
            throw Error("cascades: the Vulkan gather with split cones needs "
                        "CascadeVolume::prepareFarCones first");
        state[std::size_t(i)] = {level.farStamp, level.far.size()};
    }
    bool farSky = mSkyPerCone.has_value();
    for (int i = 0; i < n; ++i)
        farSky = farSky && volume.getLevel(i).farSky.size() == volume.getLevel(i).far.size();
    state[std::size_t(n)] = {farSky ? 1 : 0, 0};
    mFarSkyUploaded = farSky;
    if (state == mUploadedFar && mFarSlots.isValid())
        return;
    std::vector<std::uint32_t> slots(levelVoxels * std::size_t(n), ~0u);
    std::vector<glm::vec4> cones, sky;
    for (int i = 0; i < n; ++i) {
        const auto& level = volume.getLevel(i);
        const std::uint32_t base = std::uint32_t(cones.size() / kConeCount);
        for (std::size_t v = 0; v < level.farSlot.size(); ++v)
            if (level.farSlot[v] != ~0u)
                slots[std::size_t(i) * levelVoxels + v] = base + level.farSlot[v];
        for (const glm::vec3& c : level.far)
            cones.emplace_back(c, 0.0f);
        if (farSky)
            for (const glm::vec3& c : level.farSky)
                sky.emplace_back(c, 0.0f);
    }
    const std::size_t slotBytes = slots.size() * sizeof(std::uint32_t);
    const std::size_t coneBytes = std::max<std::size_t>(cones.size(), 1) * sizeof(glm::vec4);
    if (!mFarSlots.isValid() || mFarSlots.getSize() < slotBytes)
        mFarSlots = mDispatch.makeBuffer(slotBytes, "cascades.far_slots");
    if (!mFarCones.isValid() || mFarCones.getSize() < coneBytes)
        mFarCones = mDispatch.makeBuffer(coneBytes, "cascades.far_cones");
    mFarSlots.uploadSpan<std::uint32_t>(slots);
    if (!cones.empty())
        mFarCones.uploadSpan<glm::vec4>(cones);
    if (!sky.empty()) {
        if (mFarSky.getSize() < coneBytes)
            mFarSky = mDispatch.makeBuffer(coneBytes, "cascades.far_sky");
        mFarSky.uploadSpan<glm::vec4>(sky);
    }
    mLastUploadBytes += slotBytes + (cones.size() + sky.size()) * sizeof(glm::vec4);
    mUploadedFar = std::move(state);
}

} // namespace rtlab::voxelgi
