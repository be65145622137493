#include "cascade_volume.h"

#include "core/error.h"
#include "core/hash.h"
#include "families/voxel_gi/upsample.h"

#include <glm/common.hpp>
#include <glm/gtc/constants.hpp>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <string>

namespace rtlab::voxelgi {

namespace {

// The face a cone travelling along +axis sees is the voxel's -axis face, and the other way.
int getFaceSeen(int axis, double d)
{
    return 2 * axis + (d > 0.0 ? 1 : 0);
}

std::string formatShift(const glm::ivec3& s)
{
    return "(" + std::to_string(s.x) + ", " + std::to_string(s.y) + ", " + std::to_string(s.z) + ")";
}

} // namespace

CascadeVolume::CascadeVolume(CascadeSettings settings)
    : mSettings(settings), mCones(ConeSet::make(settings.coneHalfAngleDegrees))
{
    if (mSettings.levels < 1 || mSettings.levels > 12)
        throw Error("cascades: levels must be in [1, 12], found " + std::to_string(mSettings.levels));
    if (mSettings.resolution < 4 || mSettings.resolution % 2 != 0)
        throw Error("cascades: resolution must be even and at least 4, found " +
                    std::to_string(mSettings.resolution));
    if (!(mSettings.voxelSize > 0.0) || !std::isfinite(mSettings.voxelSize))
        throw Error("cascades: voxel size must be positive and finite");
    if (mSettings.bounces < 1 || mSettings.bounces > 3)
        throw Error("cascades: bounces must be in [1, 3], found " + std::to_string(mSettings.bounces));
    mLevels.resize(std::size_t(mSettings.levels));
}

VoxelRegion CascadeVolume::computeRegion(int level, const glm::dvec3& camera) const
{
    const double v = mSettings.voxelSize * std::ldexp(1.0, level);
    const double snap = 2.0 * v;
    VoxelRegion r;
    r.voxelSize = v;
    r.resolution = mSettings.resolution;
    const glm::dvec3 centre = glm::floor(camera / snap + 0.5) * snap;
    r.origin = centre - 0.5 * double(mSettings.resolution) * v;
    return r;
}

std::vector<int> CascadeVolume::getDueLevels(int frame) const
{
    std::vector<int> due;
    const int n = getLevelCount();
    if (mFirstFrame < 0 || frame <= mFirstFrame || !mSettings.oneLevelPerFrame) {
        for (int i = n - 1; i >= 0; --i)
            due.push_back(i);
        return due;
    }
    // Level i every 2^(i+1) frames, one level per frame ("Cascade Update").
    const unsigned r = unsigned(frame - mFirstFrame);
    due.push_back(std::min(n - 1, std::countr_zero(r)));
    return due;
}

void CascadeVolume::trackGeometryChange(const scene::RenderScene& geometry,
                                        const std::string& geometryKey)
{
    if (geometryKey == mTrianglesKey)
        return;
    std::vector<TriangleKey> keys(geometry.triangleCount());
    for (std::size_t t = 0; t < keys.size(); ++t) {
        Hasher h;
        glm::vec3 lo(1e30f), hi(-1e30f);
        for (int k = 0; k < 3; ++k) {
            const glm::vec3 p = geometry.positions[geometry.indices[3 * t + std::size_t(k)]];
            h.addValue(p);
            lo = glm::min(lo, p);
            hi = glm::max(hi, p);
        }
        h.addValue(geometry.triangleMaterial[t]);
        const std::string digest = h.hexDigest();
        keys[t] = {std::stoull(digest.substr(0, 16), nullptr, 16), lo, hi};
    }
    std::sort(keys.begin(), keys.end());
    if (!mTrianglesKey.empty() && !mTrianglesStale) {
        // The symmetric difference of the two sorted triangle sets: what a dig (or any edit)
        // added or removed. Triangles kept unchanged by the re-mesh do not count.
        glm::dvec3 lo(1e300), hi(-1e300);
        std::size_t i = 0, j = 0;
        const auto add = [&](const TriangleKey& k) {
            lo = glm::min(lo, glm::dvec3(k.lo));
            hi = glm::max(hi, glm::dvec3(k.hi));
        };
        while (i < mTriangles.size() || j < keys.size()) {
            if (j == keys.size() || (i < mTriangles.size() && mTriangles[i].hash < keys[j].hash))
                add(mTriangles[i++]);
            else if (i == mTriangles.size() || keys[j].hash < mTriangles[i].hash)
                add(keys[j++]);
            else {
                ++i;
                ++j;
            }
        }
        for (Level& level : mLevels) {
            level.changedMin = glm::min(level.changedMin, lo);
            level.changedMax = glm::max(level.changedMax, hi);
        }
    }
    mTriangles = std::move(keys);
    mTrianglesKey = geometryKey;
    mTrianglesStale = false;
}

bool CascadeVolume::noteGeometryChange(const std::string& fromKey, const std::string& toKey,
                                       const glm::dvec3& lo, const glm::dvec3& hi)
{
    if (mTrianglesKey.empty() || fromKey != mTrianglesKey)
        return false;
    if (toKey == mTrianglesKey)
        return true;
    for (Level& level : mLevels) {
        level.changedMin = glm::min(level.changedMin, lo);
        level.changedMax = glm::max(level.changedMax, hi);
    }
    mTriangles.clear();
    mTrianglesKey = toKey;
    mTrianglesStale = true;
    return true;
}

std::string CascadeVolume::voxelize(const scene::RenderScene& geometry,
                                    const std::string& geometryKey, const glm::dvec3& camera,
                                    int frame, bool force, const Voxelizer& voxelizer)
{
    const auto voxelizeRegion = [&](const VoxelRegion& region, const VoxelizeOptions& options) {
        return voxelizer ? voxelizer(geometry, region, options) : voxelizeTriangles(geometry, region, options);
    };
    if (mFirstFrame < 0)
        mFirstFrame = frame;
    trackGeometryChange(geometry, geometryKey);
    mCounters.levelsVoxelized = 0;
    mCounters.changedVoxels = 0;
    mCounters.changedMs = 0.0;
    std::string what;
    for (const int i : getDueLevels(frame)) {
        Level& level = mLevels[std::size_t(i)];
        const VoxelRegion region = computeRegion(i, camera);
        std::string why;
        glm::ivec3 shift(0);
        if (!level.voxelized)
            why = "first voxelization";
        else if (!(region == level.region)) {
            shift = glm::ivec3(glm::round((region.origin - level.region.origin) / region.voxelSize));
            why = "scrolled by " + formatShift(shift) + " voxels";
        } else if (geometryKey != level.geometryKey)
            why = "geometry changed";
        else if (force)
            why = "culling off";
        else
            continue;
        Level old = std::move(level);
        level = Level{};
        level.region = region;
        level.centre = region.origin + 0.5 * double(region.resolution) * region.voxelSize;
        const int R = region.resolution;
        // What changed is known when the geometry is the same, or when the triangles that
        // changed are (trackGeometryChange's box): then the old voxels are kept (shifted when
        // the level scrolled) and only the new slabs and the changed box are voxelized.
        const bool geometryChanged = geometryKey != old.geometryKey;
        const bool changeKnown = !geometryChanged || old.changedMin.x <= old.changedMax.x;
        const bool incremental = old.voxelized && !force && changeKnown &&
                                 glm::all(glm::lessThan(glm::abs(shift), glm::ivec3(R)));
        // The box of voxels the changed triangles touch, one voxel wider (a voxel's solid fill
        // and coverage depend on the rays through its column), in the new region.
        glm::ivec3 dugBegin(0), dugEnd(0);
        if (incremental && geometryChanged) {
            dugBegin = glm::clamp(
                glm::ivec3(glm::floor((old.changedMin - region.origin) / region.voxelSize)) - 1,
                glm::ivec3(0), glm::ivec3(R));
            dugEnd = glm::clamp(
                glm::ivec3(glm::floor((old.changedMax - region.origin) / region.voxelSize)) + 2,
                dugBegin, glm::ivec3(R));
        }
        const bool dugInside = glm::all(glm::lessThan(dugBegin, dugEnd));
        if (incremental && geometryChanged && shift == glm::ivec3(0) && !dugInside) {
            // The change lies outside the level: its voxels, and so its light, are what they were.
            // The level is kept as it is (no new voxel stamp: the light injection and the finer
            // levels that read it have nothing to redo).
            level = std::move(old);
            level.geometryKey = geometryKey;
            level.changedMin = glm::dvec3(1e300);
            level.changedMax = glm::dvec3(-1e300);
            what +=
                (what.empty() ? "" : "; ") + std::string("level ") + std::to_string(i) + ": " +
                why +
                ": the change lies outside the level, nothing re-voxelized (voxels and light kept)";
            continue;
        }
        if (incremental) {
            // Keep the voxels the old region shares with the new one and voxelize only the new
            // slabs ("Voxelize if Cascade level has moved": the geometry at the edges) and
            // "any geometry that has just appeared or been changed" (the dug region).
            level.grid = shiftVoxelGrid(old.grid, region, shift);
            std::size_t slabVoxels = 0;
            for (int a = 0; a < 3; ++a) {
                if (shift[a] == 0)
                    continue;
                VoxelizeOptions options{.supersampling = mSettings.supersampling,
                                        .solid = mSettings.solid};
                options.boxBegin[a] = shift[a] > 0 ? R - shift[a] : 0;
                options.boxEnd[a] = shift[a] > 0 ? R : -shift[a];
                const VoxelGrid slab = voxelizeRegion(region, options);
                pasteVoxelBox(slab, options.boxBegin, options.boxEnd, level.grid);
            }
            // The slabs' union: every voxel outside the box the old region shares.
            const glm::ivec3 kept = glm::ivec3(R) - glm::abs(shift);
            slabVoxels = region.getVoxelCount() -
                         std::size_t(kept.x) * std::size_t(kept.y) * std::size_t(kept.z);
            std::size_t boxVoxels = 0;
            if (dugInside) {
                const auto begin = std::chrono::steady_clock::now();
                VoxelizeOptions options{.supersampling = mSettings.supersampling,
                                        .solid = mSettings.solid};
                options.boxBegin = dugBegin;
                options.boxEnd = dugEnd;
                pasteVoxelBox(voxelizeRegion(region, options), dugBegin, dugEnd, level.grid);
                const glm::ivec3 extent = dugEnd - dugBegin;
                boxVoxels = std::size_t(extent.x) * std::size_t(extent.y) * std::size_t(extent.z);
                mCounters.changedVoxels += boxVoxels;
                mCounters.changedMs += std::chrono::duration<double, std::milli>(
                                           std::chrono::steady_clock::now() - begin)
                                           .count();
            }
            finalizeVoxelGrid(level.grid); // the list of surface voxels, which the copy lacks
            const std::string total = std::to_string(region.getVoxelCount());
            if (shift != glm::ivec3(0))
                why += ", voxelized the new slabs (" + std::to_string(slabVoxels) + " of " + total +
                       " voxels)";
            if (geometryChanged && dugInside)
                why += std::string(shift != glm::ivec3(0) ? " and" : ":") +
                       " re-voxelized the changed region (" + std::to_string(boxVoxels) + " of " +
                       total + " voxels)";
            else if (geometryChanged)
                why += " (the geometry's change lies outside the level)";
        } else {
            level.grid = voxelizeRegion(region, {.supersampling = mSettings.supersampling,
                                                 .solid = mSettings.solid});
        }
        level.geometryKey = geometryKey;
        level.voxelized = true;
        level.voxelStamp = ++mStamp;
        const std::size_t faces = region.getVoxelCount() * kFaceCount;
        level.alpha.assign(faces, 0.0f);
        for (auto& field : level.light)
            field.assign(faces, glm::vec3(0.0f));
        level.lightRevision = ++mRevision;
        level.emits = false;
        for (std::size_t f = 0; f < faces; ++f) {
            level.alpha[f] = level.grid.faces[f].a;
            level.light[kEmission][f] = level.alpha[f] * level.grid.emission[f];
            level.emits = level.emits || level.light[kEmission][f] != glm::vec3(0.0f);
        }
        // Light carried over (the one-pass update builds on it): the same voxels when only the
        // geometry changed; shifted when the level scrolled, the missing edge taken from the
        // next coarser level ("Scrolling: missing edge info taken from next cascade up").
        if (old.voxelized) {
            const Level* coarser =
                i + 1 < getLevelCount() && mLevels[std::size_t(i) + 1].voxelized
                    ? &mLevels[std::size_t(i) + 1]
                    : nullptr;
            tbb::parallel_for(0, R, [&](int z) {
                for (int y = 0; y < R; ++y)
                    for (int x = 0; x < R; ++x) {
                        const glm::ivec3 o = glm::ivec3(x, y, z) + shift;
                        const std::size_t vox = region.index(x, y, z);
                        const bool inside = o.x >= 0 && o.y >= 0 && o.z >= 0 && o.x < R &&
                                            o.y < R && o.z < R;
                        for (int face = 0; face < kFaceCount; ++face) {
                            const std::size_t f = vox * kFaceCount + std::size_t(face);
                            if (level.alpha[f] <= 0.0f)
                                continue;
                            for (int field = kDirect; field < kFieldCount; ++field) {
                                glm::vec3 radiance(0.0f);
                                if (inside) {
                                    const std::size_t g =
                                        old.region.index(o.x, o.y, o.z) * kFaceCount +
                                        std::size_t(face);
                                    if (old.alpha[g] > 0.0f)
                                        radiance = old.light[std::size_t(field)][g] / old.alpha[g];
                                } else if (coarser) {
                                    const glm::dvec3 c = region.getVoxelCentre(x, y, z);
                                    const VoxelRegion& cr = coarser->region;
                                    const glm::ivec3 ci = glm::clamp(
                                        glm::ivec3(glm::floor((c - cr.origin) / cr.voxelSize)),
                                        glm::ivec3(0), glm::ivec3(cr.resolution - 1));
                                    const std::size_t g =
                                        cr.index(ci.x, ci.y, ci.z) * kFaceCount + std::size_t(face);
                                    if (coarser->alpha[g] > 0.0f)
                                        radiance =
                                            coarser->light[std::size_t(field)][g] / coarser->alpha[g];
                                }
                                level.light[std::size_t(field)][f] = level.alpha[f] * radiance;
                            }
                        }
                    }
            });
        }
        // Solid voxels mirror the light of their nearest surface voxel (breadth-first through
        // the solid; propagateInward). The talk propagates the surface attributes one layer in;
        // light is carried through the whole solid so that a cone whose footprint reaches
        // deeper into a wall sees the wall's surface light, not black.
        {
            std::vector<std::uint32_t> source(region.getVoxelCount(), ~0u);
            std::vector<std::uint32_t> queue;
            for (const std::uint32_t v : level.grid.surfaceVoxels) {
                source[v] = v;
                queue.push_back(v);
            }
            for (std::size_t head = 0; head < queue.size(); ++head) {
                const std::uint32_t v = queue[head];
                const int x = int(v % std::uint32_t(R)), y = int((v / std::uint32_t(R)) % std::uint32_t(R)),
                          z = int(v / (std::uint32_t(R) * std::uint32_t(R)));
                for (int face = 0; face < kFaceCount; ++face) {
                    glm::ivec3 c(x, y, z);
                    c[face / 2] += (face % 2 == 0) ? 1 : -1;
                    if (c[face / 2] < 0 || c[face / 2] >= R)
                        continue;
                    const std::size_t n = region.index(c.x, c.y, c.z);
                    if (!(level.grid.flags[n] & kVoxelSolid) || source[n] != ~0u)
                        continue;
                    source[n] = source[v];
                    queue.push_back(std::uint32_t(n));
                    level.inward.emplace_back(std::uint32_t(n), source[v]);
                }
            }
        }
        propagateInward(level);
        if (mSettings.precombine)
            updateCombined(level);
        ++mCounters.levelsVoxelized;
        what += (what.empty() ? "" : "; ") + std::string("level ") + std::to_string(i) + ": " + why;
    }
    return what;
}

bool CascadeVolume::isStale(int i) const
{
    const Level& level = mLevels[std::size_t(i)];
    if (!level.voxelized)
        return false;
    for (int j = i; j < getLevelCount(); ++j) {
        const Level& other = mLevels[std::size_t(j)];
        if (other.voxelStamp > level.litStamp)
            return true;
        if (j > i && other.lightStamp > level.litStamp)
            return true;
    }
    // The one-pass update needs one update per bounce to carry light through its own buffers.
    return mSettings.onePass && level.litCount < mSettings.bounces;
}

std::string CascadeVolume::injectLight(const scene::RenderScene& geometry,
                                       const std::string& lightsKey, int frame, bool force,
                                       const IrradianceGather& gather)
{
    mCounters.levelsLit = 0;
    mCounters.surfaceVoxelsLit = 0;
    mCounters.injectConesMs = 0.0;
    if (lightsKey != mLightsKey) {
        mLightsKey = lightsKey;
        for (Level& level : mLevels) {
            level.litStamp = 0;
            level.litCount = 0;
        }
    }
    std::string what;
    // Coarse levels first: a level's cones read its own and coarser levels.
    for (const int i : getDueLevels(frame)) {
        Level& level = mLevels[std::size_t(i)];
        if (!level.voxelized)
            continue;
        const bool stale = isStale(i);
        if (!stale && !force)
            continue;
        bool inputsChanged = level.litStamp == 0;
        for (int j = i; j < getLevelCount() && !inputsChanged; ++j)
            inputsChanged = mLevels[std::size_t(j)].voxelStamp > level.litStamp ||
                            (j > i && mLevels[std::size_t(j)].lightStamp > level.litStamp);
        lightLevel(i, geometry, gather);
        level.litCount = inputsChanged ? 1 : level.litCount + 1;
        level.litStamp = ++mStamp;
        level.lightStamp = level.litStamp;
        ++mCounters.levelsLit;
        mCounters.surfaceVoxelsLit += level.grid.surfaceVoxels.size();
        what += (what.empty() ? "" : "; ") + std::string("level ") + std::to_string(i) +
                (stale ? "" : " (culling off)");
    }
    return what;
}

InjectionSettings CascadeVolume::getInjectionSettings() const
{
    InjectionSettings settings;
    settings.startOffset = mSettings.startOffset;
    settings.march.stepScale = mSettings.stepScale;
    return settings;
}

void CascadeVolume::lightLevel(int i, const scene::RenderScene& geometry, const IrradianceGather& gather)
{
    Level& level = mLevels[std::size_t(i)];
    const FieldSampler sampler{this};
    InjectionLights lights;
    lights.pointLights = &geometry.pointLights;
    lights.hasSky = geometry.sky.emits();
    if (lights.hasSky)
        lights.skyPerCone = computeSkyPerCone(geometry.sky, mCones);
    const InjectionSettings settings = getInjectionSettings();

    const auto& surface = level.grid.surfaceVoxels;
    const int R = level.region.resolution;
    // The passes of one update: the three-pass schedule traces direct, then the first bounce
    // from the new direct buffer, then the second; the one-pass schedule traces once and writes
    // every buffer from the previous ones ("One Pass Strategy").
    const int passes = mSettings.onePass ? 1 : mSettings.bounces;
    std::vector<FaceIrradiance> irradiance;
    for (int pass = 0; pass < passes; ++pass) {
        // Every surface voxel's 16 cones and shadow cones, from the buffers as they are now.
        irradiance.resize(surface.size());
        const auto start = std::chrono::steady_clock::now();
        if (gather) {
            gather(i, lights, irradiance);
            if (irradiance.size() != surface.size())
                throw Error("cascades: the injection gave " + std::to_string(irradiance.size()) +
                            " voxels' irradiance for " + std::to_string(surface.size()) + " surface voxels");
        } else {
            tbb::parallel_for(std::size_t(0), surface.size(), [&](std::size_t s) {
                const std::uint32_t vox = surface[s];
                const int x = int(vox % std::uint32_t(R));
                const int y = int((vox / std::uint32_t(R)) % std::uint32_t(R));
                const int z = int(vox / (std::uint32_t(R) * std::uint32_t(R)));
                InjectionVoxel v;
                v.centre = level.region.getVoxelCentre(x, y, z);
                v.normal = level.grid.normal[vox];
                v.voxelSize = level.region.voxelSize;
                v.faces = &level.grid.faces[std::size_t(vox) * kFaceCount];
                irradiance[s] = gatherVoxelIrradiance(sampler, v, mCones, lights, settings);
            });
        }
        mCounters.injectConesMs +=
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
        std::array<std::vector<glm::vec3>, kFieldCount> next = level.light;
        tbb::parallel_for(std::size_t(0), surface.size(), [&](std::size_t s) {
            const std::uint32_t vox = surface[s];
            const FaceIrradiance& e = irradiance[s];
            for (int face = 0; face < kFaceCount; ++face) {
                const std::size_t f = std::size_t(vox) * kFaceCount + std::size_t(face);
                const glm::vec4& g = level.grid.faces[f];
                const glm::vec3 reflect = glm::vec3(g) * (g.a / glm::pi<float>());
                for (int field = kDirect; field < kDirect + mSettings.bounces; ++field) {
                    const bool written = mSettings.onePass || field == kDirect + pass;
                    if (written)
                        next[std::size_t(field)][f] = reflect * e.e[std::size_t(field)][std::size_t(face)];
                }
            }
        });
        level.light = std::move(next);
        propagateInward(level);
        level.lightRevision = ++mRevision;
    }
    if (mSettings.precombine)
        updateCombined(level);
}

void CascadeVolume::propagateInward(Level& level)
{
    for (const auto& [solid, surface] : level.inward) {
        const std::size_t base = std::size_t(surface) * kFaceCount;
        // The surface voxel's radiance per face; a face it does not cover takes its mean.
        std::array<glm::vec3, kFieldCount> mean{};
        float covered = 0.0f;
        for (int face = 0; face < kFaceCount; ++face)
            if (const float a = level.alpha[base + std::size_t(face)]; a > 0.0f) {
                for (int field = 0; field < kFieldCount; ++field)
                    mean[std::size_t(field)] += level.light[std::size_t(field)][base + std::size_t(face)] / a;
                covered += 1.0f;
            }
        for (int face = 0; face < kFaceCount; ++face) {
            const std::size_t g = base + std::size_t(face);
            const std::size_t f = std::size_t(solid) * kFaceCount + std::size_t(face);
            const float a = level.alpha[g];
            for (int field = 0; field < kFieldCount; ++field)
                level.light[std::size_t(field)][f] =
                    a > 0.0f ? level.light[std::size_t(field)][g] / a
                             : (covered > 0.0f ? mean[std::size_t(field)] / covered : glm::vec3(0.0f));
        }
    }
}

void CascadeVolume::updateCombined(Level& level)
{
    const std::size_t voxels = level.region.getVoxelCount();
    level.combined.assign(voxels * kConeCount, glm::vec4(0.0f));
    tbb::parallel_for(std::size_t(0), voxels, [&](std::size_t vox) {
        for (int k = 0; k < kConeCount; ++k) {
            const glm::dvec3& d = mCones.directions[std::size_t(k)];
            glm::vec4 c(0.0f);
            for (int axis = 0; axis < 3; ++axis) {
                const float w = float(d[axis] * d[axis]);
                const std::size_t f = vox * kFaceCount + std::size_t(getFaceSeen(axis, d[axis]));
                c += w * glm::vec4(getGatheredLight(level, f), level.alpha[f]);
            }
            level.combined[std::size_t(k) * voxels + vox] = c;
        }
    });
}

glm::vec3 CascadeVolume::getGatheredLight(const Level& level, std::size_t f) const
{
    glm::vec3 light(0.0f);
    for (int field = kDirect; field < kDirect + mSettings.bounces; ++field)
        light += level.light[std::size_t(field)][f];
    // "Extra Magic" (the talk): one more bounce extrapolated from the last two.
    if (mSettings.extrapolate && mSettings.bounces >= 2)
        light += extrapolateBounce(level.light[std::size_t(kDirect + mSettings.bounces - 2)][f],
                                   level.light[std::size_t(kDirect + mSettings.bounces - 1)][f]);
    return light;
}

namespace {

// pcg3d (Jarzynski and Olano, "Hash Functions for GPU Rendering", JCGT 2020), to 24 bits so
// that the float conversion is exact on every device.
float hashToUnit(glm::uvec3 v)
{
    v = v * 1664525u + 1013904223u;
    v.x += v.y * v.z;
    v.y += v.z * v.x;
    v.z += v.x * v.y;
    v ^= v >> 16u;
    v.x += v.y * v.z;
    v.y += v.z * v.x;
    v.z += v.x * v.y;
    return float(v.x >> 8u) * (1.0f / 16777216.0f);
}

} // namespace

float computeValueNoise(const glm::ivec3& cell, const glm::vec3& f)
{
    float n = 0.0f;
    for (int corner = 0; corner < 8; ++corner) {
        const glm::ivec3 d(corner & 1, (corner >> 1) & 1, (corner >> 2) & 1);
        const float w = (d.x ? f.x : 1.0f - f.x) * (d.y ? f.y : 1.0f - f.y) * (d.z ? f.z : 1.0f - f.z);
        n += w * hashToUnit(glm::uvec3(cell + d));
    }
    return n;
}

double CascadeVolume::selectLevel(const glm::dvec3& p, double diameter, bool noisy) const
{
    const int n = getLevelCount();
    double containing = -1.0;
    for (int i = 0; i < n; ++i) {
        const Level& level = mLevels[std::size_t(i)];
        if (!level.voxelized)
            continue;
        // A sphere inside the level, one voxel in from its faces (trilinear footprint).
        const double radius = (0.5 * level.region.resolution - 1.0) * level.region.voxelSize;
        const glm::dvec3 offset = p - level.centre;
        const double d2 = glm::dot(offset, offset);
        if (d2 > 1.001 * (radius * radius))
            continue; // outside by more than rounding: the test below would fail too
        const double r = std::sqrt(d2) / radius;
        if (r <= 1.0) {
            // From half the radius on, blend toward the next level ("Cascade selection"), with
            // the talk's "3D noise offset" on the blend (the containment test stays exact).
            double blend = r;
            if (noisy && mSettings.levelNoise > 0.0) {
                const glm::dvec3 u = p / mSettings.voxelSize;
                const glm::dvec3 cell = glm::floor(u);
                // (Cells beyond the int range, 2^30 voxels out, get no noise.)
                if (std::max({std::abs(cell.x), std::abs(cell.y), std::abs(cell.z)}) < 1073741824.0)
                    blend += mSettings.levelNoise *
                             (2.0 * double(computeValueNoise(glm::ivec3(cell), glm::vec3(u - cell))) - 1.0);
            }
            containing = i + (i + 1 < n ? std::clamp((blend - 0.5) / 0.5, 0.0, 1.0) : 0.0);
            break;
        }
    }
    if (containing < 0.0)
        return -1.0;
    const double footprint =
        diameter > mSettings.voxelSize ? std::log2(diameter / mSettings.voxelSize) : 0.0;
    return std::min(double(n - 1), std::max(containing, footprint));
}

void CascadeVolume::getTrilinear(const VoxelRegion& r, const glm::dvec3& p,
                                 std::array<std::size_t, 8>& voxels, std::array<double, 8>& weights)
{
    // The lattice of the voxel centres, clamped to the region (sampleLevel, sampleFar).
    const int R = r.resolution;
    glm::dvec3 c = (p - r.origin) / r.voxelSize - 0.5;
    glm::ivec3 i0;
    glm::dvec3 t;
    for (int a = 0; a < 3; ++a) {
        c[a] = std::clamp(c[a], 0.0, double(R - 1));
        i0[a] = std::min(int(std::floor(c[a])), R - 2);
        t[a] = c[a] - i0[a];
    }
    for (int corner = 0; corner < 8; ++corner) {
        const int dx = corner & 1, dy = (corner >> 1) & 1, dz = (corner >> 2) & 1;
        weights[std::size_t(corner)] =
            (dx ? t.x : 1.0 - t.x) * (dy ? t.y : 1.0 - t.y) * (dz ? t.z : 1.0 - t.z);
        voxels[std::size_t(corner)] = r.index(i0.x + dx, i0.y + dy, i0.z + dz);
    }
}

void CascadeVolume::sampleLevel(const Level& level, const glm::dvec3& p, int cone,
                                const glm::dvec3& dir, bool gathered, float weight,
                                ConeSample& out) const
{
    std::array<std::size_t, 8> voxels;
    std::array<double, 8> weights;
    getTrilinear(level.region, p, voxels, weights);
    const bool combined = gathered && cone >= 0 && !level.combined.empty();
    const glm::vec4* coneRow =
        combined ? level.combined.data() + std::size_t(cone) * (level.combined.size() / kConeCount)
                 : nullptr;
    for (int corner = 0; corner < 8; ++corner) {
        const double w = weights[std::size_t(corner)];
        if (w == 0.0)
            continue;
        const float fw = float(w) * weight;
        const std::size_t vox = voxels[std::size_t(corner)];
        if (combined) {
            const glm::vec4& v = coneRow[vox];
            out.alpha += fw * v.a;
            // The optical depth per face, blended as the faces were (cone_tracing.h ConeSample).
            for (int axis = 0; axis < 3 && out.wantsDepth; ++axis) {
                const std::size_t f = vox * kFaceCount + std::size_t(getFaceSeen(axis, dir[axis]));
                out.depth += fw * float(dir[axis] * dir[axis]) * computeOpticalDepth(level.alpha[f]);
            }
            out.light[kDirect] += fw * glm::vec3(v);
            if (level.emits)
                for (int axis = 0; axis < 3; ++axis) {
                    const std::size_t f = vox * kFaceCount + std::size_t(getFaceSeen(axis, dir[axis]));
                    out.light[kEmission] += fw * float(dir[axis] * dir[axis]) * level.light[kEmission][f];
                }
            continue;
        }
        for (int axis = 0; axis < 3; ++axis) {
            const float aw = fw * float(dir[axis] * dir[axis]);
            if (aw == 0.0f)
                continue;
            const std::size_t f = vox * kFaceCount + std::size_t(getFaceSeen(axis, dir[axis]));
            out.alpha += aw * level.alpha[f];
            if (out.wantsDepth)
                out.depth += aw * computeOpticalDepth(level.alpha[f]);
            if (gathered) {
                out.light[kDirect] += aw * getGatheredLight(level, f);
                if (level.emits)
                    out.light[kEmission] += aw * level.light[kEmission][f];
            } else {
                for (int field = 0; field < kFieldCount; ++field)
                    out.light[std::size_t(field)] += aw * level.light[std::size_t(field)][f];
            }
        }
    }
}

template <bool Gathered>
bool CascadeVolume::sampleAt(const glm::dvec3& p, double diameter, int cone, const glm::dvec3& dir,
                             ConeSample& out) const
{
    const double l = selectLevel(p, diameter, Gathered);
    if (l < 0.0)
        return false;
    out.clear();
    const int l0 = int(std::floor(l));
    const float frac = float(l - l0);
    sampleLevel(mLevels[std::size_t(l0)], p, cone, dir, Gathered, 1.0f - frac, out);
    if (frac > 0.0f && l0 + 1 < getLevelCount())
        sampleLevel(mLevels[std::size_t(l0) + 1], p, cone, dir, Gathered, frac, out);
    out.voxelSize = mSettings.voxelSize * std::exp2(l);
    return true;
}

bool CascadeVolume::sampleFields(const glm::dvec3& p, double diameter, int cone,
                                 const glm::dvec3& dir, ConeSample& out) const
{
    return sampleAt<false>(p, diameter, cone, dir, out);
}

bool CascadeVolume::sampleGathered(const glm::dvec3& p, double diameter, int cone,
                                   const glm::dvec3& dir, ConeSample& out) const
{
    return sampleAt<true>(p, diameter, cone, dir, out);
}

std::size_t CascadeVolume::getPayloadBytes() const
{
    std::size_t bytes = 0;
    for (const Level& l : mLevels) {
        bytes += l.grid.faces.size() * sizeof(glm::vec4) + l.grid.emission.size() * sizeof(glm::vec3) +
                 l.grid.normal.size() * sizeof(glm::vec3) + l.grid.flags.size();
        bytes += l.alpha.size() * sizeof(float);
        for (const auto& f : l.light)
            bytes += f.size() * sizeof(glm::vec3);
        bytes += l.combined.size() * sizeof(glm::vec4);
        bytes += l.far.size() * sizeof(glm::vec3) + l.farSlot.size() * sizeof(std::uint32_t);
    }
    return bytes;
}

std::size_t CascadeVolume::getTopologyBytes() const
{
    // A dense cascade has no topology beyond each level's placement.
    return mLevels.size() * sizeof(VoxelRegion);
}

} // namespace rtlab::voxelgi
