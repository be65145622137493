// The C++ pixel gather of the cascades: the cones (or, for the error split, rays) from every
// G-buffer pixel through the levels (cascade_volume.h; the Vulkan twin is cascade_gather_gpu.h).

#include "cascade_volume.h"

#include "core/error.h"
#include "families/voxel_gi/pixel_cones.h"
#include "families/voxel_gi/upsample.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>

namespace rtlab::voxelgi {

bool CascadeVolume::preparePixel(const scene::GBuffer& gbuffer, int x, int y, glm::dvec3& origin,
                                 glm::dvec3& n, ConeMarchSettings& march, double* startLevel) const
{
    glm::dvec3 p;
    if (!readPixelSurface(gbuffer, x, y, p, n))
        return false;
    const double start = selectLevel(p, 0.0, true);
    if (start < 0.0)
        return false;
    // Start a voxel of the pixel's start level out, along the normal and along the cone.
    const double v = mSettings.voxelSize * std::exp2(std::floor(start));
    march.stepScale = mSettings.stepScale;
    march.startDistance = mSettings.startOffset * v;
    march.skyStartDistance = mSettings.skyStart * v;
    march.skyOpticalDepth = mSettings.skyOpticalDepth;
    march.skyPlaneNormal = n;
    march.skyPlaneHeight = 0.5 * mSettings.startOffset * v;
    origin = p + n * (0.5 * mSettings.startOffset * v);
    if (startLevel != nullptr)
        *startLevel = start;
    return true;
}

void CascadeVolume::computeStartLevels(const scene::GBuffer& gbuffer,
                                       Image<std::uint8_t>& levels) const
{
    levels = Image<std::uint8_t>(gbuffer.width, gbuffer.height, 255);
    tbb::parallel_for(0, gbuffer.height, [&](int y) {
        for (int x = 0; x < gbuffer.width; ++x) {
            glm::dvec3 p, n;
            if (!readPixelSurface(gbuffer, x, y, p, n))
                continue;
            const double start = selectLevel(p, 0.0, true);
            if (start >= 0.0)
                levels.at(x, y) = std::uint8_t(std::floor(start));
        }
    });
}

void CascadeVolume::gather(const scene::GBuffer& gbuffer,
                           const std::vector<Image<float>>* coneVisibility, Image<glm::vec3>& out)
{
    std::vector<glm::vec3> cones;
    gatherCones(gbuffer, cones);
    const ReducedGBuffer same = reduceGBuffer(gbuffer, 1);
    ConeCombineInputs in;
    in.coneRadiance = &cones;
    in.reduced = &same;
    in.full = &gbuffer;
    in.visibility = coneVisibility;
    in.coneHalfAngle = mCones.halfAngle;
    out = combineCones(in);
}

namespace {

double millisecondsSince(std::chrono::steady_clock::time_point start)
{
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

} // namespace

void CascadeVolume::gatherCones(const scene::GBuffer& gbuffer, std::vector<glm::vec3>& out,
                                const ConeSkyOutput* sky)
{
    if (mSettings.farStart > 0.0) {
        gatherConesSplit(gbuffer, out, sky);
        return;
    }
    mCounters.farConesTraced = 0;
    mCounters.farVoxelsCached = 0;
    mCounters.farConesMs = 0.0;
    const auto start = std::chrono::steady_clock::now();
    const auto prepare = [this](const scene::GBuffer& g, int x, int y, glm::dvec3& origin,
                                glm::dvec3& n, ConeMarchSettings& march) {
        return preparePixel(g, x, y, origin, n, march);
    };
    mCounters.meanStepsPerCone =
        traceGBufferCones(gbuffer, mCones, prepare, GatheredSampler{this, true}, out, sky);
    mCounters.pixelConesMs = millisecondsSince(start);
}

void CascadeVolume::gatherRays(const scene::GBuffer& gbuffer, int rays, Image<glm::vec3>& out,
                               const scene::Sky* sky) const
{
    const auto prepare = [this](const scene::GBuffer& g, int x, int y, glm::dvec3& origin,
                                glm::dvec3& n, ConeMarchSettings& march) {
        return preparePixel(g, x, y, origin, n, march);
    };
    // Rays: the faces blended along each direction (no per-cone pre-combined buffer).
    traceGBufferRays(gbuffer, rays, prepare, GatheredSampler{this, false}, out, sky);
}

int CascadeVolume::getFarDependency(int i) const
{
    // A far cone of level i first samples at t = farStart * v_i with footprint 2 t tan(a), that
    // is at level i + log2(2 farStart tan(a)) (selectLevel takes the coarser of the footprint's
    // level and the point's own); later samples only coarser.
    const double footprint = std::log2(2.0 * mSettings.farStart * mCones.tanHalfAngle);
    return std::clamp(i + int(std::floor(footprint)), 0, i);
}

void CascadeVolume::invalidateFarCones()
{
    for (int i = 0; i < getLevelCount(); ++i) {
        Level& level = mLevels[std::size_t(i)];
        const std::size_t voxels = level.region.getVoxelCount();
        bool stale = level.farSlot.size() != voxels;
        for (int j = getFarDependency(i); j < getLevelCount() && !stale; ++j) {
            const Level& other = mLevels[std::size_t(j)];
            stale = std::max(other.voxelStamp, other.lightStamp) > level.farStamp;
        }
        if (!stale)
            continue;
        level.farSlot.assign(voxels, ~0u);
        level.far.clear();
        level.farSky.clear();
        level.farStamp = mStamp;
    }
}

CascadeVolume::FarNeighbourhood CascadeVolume::findFar(const Level& level,
                                                       const glm::dvec3& p) const
{
    FarNeighbourhood around;
    getTrilinear(level.region, p, around.voxels, around.weights);
    return around;
}

glm::vec3 CascadeVolume::sampleFar(const Level& level, const FarNeighbourhood& around,
                                   int cone, bool sky) const
{
    const std::vector<glm::vec3>& values = sky ? level.farSky : level.far;
    glm::dvec3 sum(0.0);
    for (int c = 0; c < 8; ++c)
        if (around.weights[std::size_t(c)] != 0.0)
            sum += around.weights[std::size_t(c)] *
                   glm::dvec3(values[std::size_t(level.farSlot[around.voxels[std::size_t(c)]]) *
                                         kConeCount +
                                     std::size_t(cone)]);
    return glm::vec3(sum);
}

// "Split Cone Trace" (the talk): two cones in the same direction from nearby points sample
// increasingly similar voxels further out, so the far part of every cone is traced once from
// each voxel centre of a level, stored in another cascade, and interpolated trilinearly; each
// pixel traces only the near part up to the split (the talk: about a metre at its 0.4 m finest
// voxels), then adds the far radiance seen through the near part's transmittance. The start
// level blends between levels l0 and l0 + 1 (selectLevel): the pixel composites its near part
// with each level's far cones at that level's split (the second near segment continues the
// first) and blends the two, so the split moves smoothly with the start level.
glm::dvec3 CascadeVolume::getVoxelCentre(int level, std::uint32_t vox) const
{
    const VoxelRegion& r = mLevels[std::size_t(level)].region;
    const std::uint32_t R = std::uint32_t(r.resolution);
    return r.getVoxelCentre(int(vox % R), int((vox / R) % R), int(vox / (R * R)));
}

void CascadeVolume::prepareFarCones(const scene::GBuffer& gbuffer, const FarConeTracer& tracer)
{
    invalidateFarCones();
    const int W = gbuffer.width, H = gbuffer.height, n = getLevelCount();
    // The voxel centres whose far cones the pixels read (the trilinear neighbourhoods of their
    // cone origins at their start levels) and that are not traced yet.
    std::vector<std::vector<std::uint8_t>> wanted(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i)
        wanted[std::size_t(i)].assign(mLevels[std::size_t(i)].farSlot.size(), 0);
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            glm::dvec3 origin, normal;
            ConeMarchSettings march;
            double start = -1.0;
            if (!preparePixel(gbuffer, x, y, origin, normal, march, &start))
                continue;
            const auto [l0, l1, frac] = getStartLevels(start);
            for (const int l : {l0, l1}) {
                if (l < 0)
                    continue;
                std::array<std::size_t, 8> voxels;
                std::array<double, 8> weights;
                getTrilinear(mLevels[std::size_t(l)].region, origin, voxels, weights);
                for (int c = 0; c < 8; ++c)
                    if (weights[std::size_t(c)] != 0.0 &&
                        mLevels[std::size_t(l)].farSlot[voxels[std::size_t(c)]] == ~0u)
                        wanted[std::size_t(l)][voxels[std::size_t(c)]] = 1;
            }
        }
    // Slots appended to each level's far buffer, in voxel order (deterministic).
    std::vector<std::pair<int, std::uint32_t>> toTrace;
    for (int i = 0; i < n; ++i) {
        Level& level = mLevels[std::size_t(i)];
        std::uint32_t slot = std::uint32_t(level.far.size() / kConeCount);
        for (std::size_t v = 0; v < wanted[std::size_t(i)].size(); ++v)
            if (wanted[std::size_t(i)][v]) {
                toTrace.emplace_back(i, std::uint32_t(v));
                level.farSlot[v] = slot++;
            }
        const std::size_t before = level.far.size();
        level.far.resize(std::size_t(slot) * kConeCount, glm::vec3(0.0f));
        // The sky beside the light while every far cone of the level has one; far cones traced
        // for a gather that wants no sky (or by a tracer that gives none) keep none, and the
        // level's sky stays empty until its far cones are dropped.
        if (mTraceSky && level.farSky.size() == before)
            level.farSky.resize(level.far.size(), glm::vec3(0.0f));
        else
            level.farSky.clear();
    }
    const GatheredSampler sampler{this, true};
    const auto farStart = std::chrono::steady_clock::now();
    if (tracer && !toTrace.empty()) {
        std::vector<glm::vec3> traced, tracedSky;
        tracer(toTrace, traced, mTraceSky ? &tracedSky : nullptr);
        if (traced.size() != toTrace.size() * kConeCount)
            throw Error("cascades: the far-cone tracer gave " + std::to_string(traced.size()) +
                        " cones for " + std::to_string(toTrace.size() * kConeCount));
        const bool withSky = tracedSky.size() == traced.size();
        for (std::size_t k = 0; k < toTrace.size(); ++k) {
            const auto [i, vox] = toTrace[k];
            Level& level = mLevels[std::size_t(i)];
            for (int c = 0; c < kConeCount; ++c) {
                const std::size_t at = std::size_t(level.farSlot[vox]) * kConeCount + std::size_t(c);
                level.far[at] = traced[k * kConeCount + std::size_t(c)];
                if (withSky && !level.farSky.empty())
                    level.farSky[at] = tracedSky[k * kConeCount + std::size_t(c)];
            }
        }
        if (!withSky)
            for (Level& level : mLevels)
                level.farSky.clear();
    }
    tbb::parallel_for(std::size_t(0), tracer ? std::size_t(0) : toTrace.size(), [&](std::size_t k) {
        const auto [i, vox] = toTrace[k];
        Level& level = mLevels[std::size_t(i)];
        const VoxelRegion& r = level.region;
        const glm::dvec3 centre = getVoxelCentre(i, vox);
        ConeMarchSettings march;
        march.tanHalfAngle = mCones.tanHalfAngle;
        march.stepScale = mSettings.stepScale;
        march.startDistance = mSettings.farStart * r.voxelSize;
        march.sky = mTraceSky;
        march.skyStartDistance = mSettings.skyStart * r.voxelSize;
        march.skyOpticalDepth = mSettings.skyOpticalDepth;
        for (int c = 0; c < kConeCount; ++c) {
            const ConeResult far = marchCone(sampler, centre, mCones.directions[std::size_t(c)], c, march);
            const std::size_t at = std::size_t(level.farSlot[vox]) * kConeCount + std::size_t(c);
            level.far[at] = glm::max(far.light[kDirect], glm::vec3(0.0f));
            if (!level.farSky.empty())
                level.farSky[at] = computeConeSkyRadiance(far, mFarSkyPerCone[std::size_t(c)]);
        }
    });
    mCounters.farConesMs = millisecondsSince(farStart);
    mCounters.farConesTraced = toTrace.size() * std::size_t(kConeCount);
    mCounters.farVoxelsCached = 0;
    for (const Level& level : mLevels)
        mCounters.farVoxelsCached += level.far.size() / kConeCount;
}

void CascadeVolume::setConeSky(const std::array<glm::vec3, kConeCount>* skyPerCone)
{
    mTraceSky = skyPerCone != nullptr;
    if (skyPerCone != nullptr && *skyPerCone != mFarSkyPerCone) {
        // Another sky: the far cones' sky is stale, so all far cones are traced again.
        mFarSkyPerCone = *skyPerCone;
        for (Level& level : mLevels) {
            level.farSlot.assign(level.region.getVoxelCount(), ~0u);
            level.far.clear();
            level.farSky.clear();
        }
    }
}

CascadeVolume::StartLevels CascadeVolume::getStartLevels(double start) const
{
    StartLevels s;
    s.l0 = int(std::floor(start));
    s.frac = start - s.l0;
    s.l1 = s.frac > 0.0 && s.l0 + 1 < getLevelCount() && mLevels[std::size_t(s.l0) + 1].voxelized
               ? s.l0 + 1
               : -1;
    return s;
}

void CascadeVolume::gatherConesSplit(const scene::GBuffer& gbuffer, std::vector<glm::vec3>& out,
                                     const ConeSkyOutput* sky)
{
    std::vector<glm::vec3>* skyOut = sky != nullptr ? sky->out : nullptr;
    setConeSky(skyOut != nullptr ? &sky->skyPerCone : nullptr);
    prepareFarCones(gbuffer);
    const int W = gbuffer.width, H = gbuffer.height;
    const GatheredSampler sampler{this, true};
    struct Start {
        glm::dvec3 origin{0.0}, normal{0.0};
        ConeMarchSettings march;
        double level = -1.0;
    };
    // The pixels: near parts, composited with the far cones.
    const auto pixelStart = std::chrono::steady_clock::now();
    out.assign(std::size_t(W) * std::size_t(H) * kConeCount, glm::vec3(0.0f));
    if (skyOut != nullptr) {
        skyOut->clear();
        const bool farSky = std::all_of(mLevels.begin(), mLevels.end(), [](const Level& l) {
            return l.farSky.size() == l.far.size();
        });
        if (farSky)
            skyOut->assign(out.size(), glm::vec3(0.0f));
        else
            skyOut = nullptr; // far cones traced on Vulkan: no sky this frame
    }
    std::vector<std::uint64_t> stepsPerRow(std::size_t(H), 0), conesPerRow(std::size_t(H), 0);
    tbb::parallel_for(0, H, [&](int y) {
        for (int x = 0; x < W; ++x) {
            const std::size_t pixel = std::size_t(y) * std::size_t(W) + std::size_t(x);
            Start s;
            if (!preparePixel(gbuffer, x, y, s.origin, s.normal, s.march, &s.level))
                continue;
            const auto [l0, l1, frac] = getStartLevels(s.level);
            const auto w = computeIrradianceWeights(mCones, s.normal);
            const double split0 = mSettings.farStart * mLevels[std::size_t(l0)].region.voxelSize;
            // The pixel's far neighbourhoods at both start levels, shared by its cones.
            const FarNeighbourhood far0 = findFar(mLevels[std::size_t(l0)], s.origin);
            const FarNeighbourhood far1 =
                l1 >= 0 ? findFar(mLevels[std::size_t(l1)], s.origin) : FarNeighbourhood{};
            for (int k = 0; k < kConeCount; ++k) {
                if (w[std::size_t(k)] == 0.0)
                    continue;
                const glm::dvec3& dir = mCones.directions[std::size_t(k)];
                ConeMarchSettings march = s.march;
                march.tanHalfAngle = mCones.tanHalfAngle;
                march.maxDistance = split0;
                march.sky = skyOut != nullptr; // else no cone marches on for the sky alone
                const ConeResult a = marchCone(sampler, s.origin, dir, k, march);
                glm::dvec3 la(a.light[kDirect]);
                stepsPerRow[std::size_t(y)] += std::uint64_t(a.steps);
                ++conesPerRow[std::size_t(y)];
                // Escaped: the cone left the cascade, nothing lies beyond it.
                if (!a.escaped)
                    la +=
                        a.transmittance * glm::dvec3(sampleFar(mLevels[std::size_t(l0)], far0, k));
                // The sky and emitters the same way (computeConeSkyRadiance): the near part's
                // emitters, then the sky where it left the cascade, else the far cones' sky and
                // emitters, through the near part's sky transmittance.
                const glm::dvec3 skyOfCone(mFarSkyPerCone[std::size_t(k)]);
                glm::dvec3 sa(0.0);
                if (skyOut != nullptr)
                    sa = glm::dvec3(a.light[kEmission]) +
                         a.skyTransmittance *
                             (a.skyEscaped ? skyOfCone
                                           : glm::dvec3(sampleFar(mLevels[std::size_t(l0)], far0, k, true)));
                glm::dvec3 result = la, skyResult = sa;
                if (l1 >= 0) {
                    glm::dvec3 lb(a.light[kDirect]), sb(a.light[kEmission]);
                    ConeResult b;
                    if (!a.escaped) {
                        ConeMarchSettings segment = march;
                        segment.startDistance = split0;
                        segment.maxDistance = 2.0 * split0;
                        b = marchCone(sampler, s.origin, dir, k, segment);
                        stepsPerRow[std::size_t(y)] += std::uint64_t(b.steps);
                        lb += a.transmittance * glm::dvec3(b.light[kDirect]);
                        if (!b.escaped)
                            lb += a.transmittance * b.transmittance *
                                  glm::dvec3(sampleFar(mLevels[std::size_t(l1)], far1, k));
                    }
                    if (skyOut != nullptr) {
                        if (a.skyEscaped) {
                            sb += a.skyTransmittance * skyOfCone;
                        } else { // then a.escaped is false too: b was marched
                            sb += a.transmittance * glm::dvec3(b.light[kEmission]) +
                                  a.skyTransmittance * b.skyTransmittance *
                                      (b.skyEscaped ? skyOfCone
                                                    : glm::dvec3(sampleFar(mLevels[std::size_t(l1)],
                                                                           far1, k, true)));
                        }
                    }
                    result = la + frac * (lb - la);
                    skyResult = sa + frac * (sb - sa);
                }
                out[pixel * kConeCount + std::size_t(k)] = glm::max(glm::vec3(result), glm::vec3(0.0f));
                if (skyOut != nullptr)
                    (*skyOut)[pixel * kConeCount + std::size_t(k)] =
                        glm::max(glm::vec3(skyResult), glm::vec3(0.0f));
            }
        }
    });
    std::uint64_t steps = 0, traced = 0;
    for (int y = 0; y < H; ++y) {
        steps += stepsPerRow[std::size_t(y)];
        traced += conesPerRow[std::size_t(y)];
    }
    mCounters.meanStepsPerCone = traced ? double(steps) / double(traced) : 0.0;
    mCounters.pixelConesMs = millisecondsSince(pixelStart);
}

} // namespace rtlab::voxelgi
