// Determinism across thread counts, the progressive stopping rule, the on-disk cache, the EXR
// round trip and bad input.
#include "reference/reference.h"

#include "reference/prepared.h"
#include "reference/progressive.h"

#include "core/error.h"
#include "test_scenes.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>

namespace rtlab::reference {
namespace {

using ::testing::HasSubstr;

template <class T> bool isBitwiseEqual(const Image<T>& a, const Image<T>& b)
{
    return a.width == b.width && a.height == b.height && a.pixels.size() == b.pixels.size() &&
           (a.pixels.empty() ||
            std::memcmp(a.pixels.data(), b.pixels.data(), a.pixels.size() * sizeof(T)) == 0);
}

//! Every image of two results is byte for byte the same.
void expectIdentical(const ReferenceResult& a, const ReferenceResult& b)
{
    EXPECT_TRUE(isBitwiseEqual(a.occlusion, b.occlusion));
    EXPECT_TRUE(isBitwiseEqual(a.occlusionStdErr, b.occlusionStdErr));
    EXPECT_TRUE(isBitwiseEqual(a.bentNormal, b.bentNormal));
    EXPECT_TRUE(isBitwiseEqual(a.bentNormalStdErr, b.bentNormalStdErr));
    EXPECT_TRUE(isBitwiseEqual(a.aperture, b.aperture));
    EXPECT_TRUE(isBitwiseEqual(a.apertureStdErr, b.apertureStdErr));
    EXPECT_TRUE(isBitwiseEqual(a.apertureUniform, b.apertureUniform));
    EXPECT_TRUE(isBitwiseEqual(a.apertureUniformStdErr, b.apertureUniformStdErr));
    EXPECT_TRUE(isBitwiseEqual(a.radiance, b.radiance));
    EXPECT_TRUE(isBitwiseEqual(a.radianceStdErr, b.radianceStdErr));
    EXPECT_TRUE(isBitwiseEqual(a.irradiance, b.irradiance));
    EXPECT_TRUE(isBitwiseEqual(a.irradianceStdErr, b.irradianceStdErr));
    EXPECT_TRUE(isBitwiseEqual(a.sampleCount, b.sampleCount));
}

struct Room {
    scene::RenderScene scene = test::makeRoomScene();
    scene::GBuffer gbuffer = test::makeRoomGBuffer(scene, 16, 16);
};

ReferenceSettings makeQuickSettings(Quantity q)
{
    ReferenceSettings s = test::makeSettings(q);
    s.radius = q == Quantity::Obscurance ? 0.5 : 1.0;
    s.batchSize = 32;
    s.maxSamples = 256;
    s.targetStdErr = 0.01;
    s.targetRelStdErr = 0.05;
    return s;
}

TEST(ReferencePipeline, ImagesAreBitwiseIdenticalForOneAndTwoThreads)
{
    const Room room;
    for (Quantity q : {Quantity::Ao, Quantity::Bent, Quantity::Full}) {
        ReferenceResult one, two;
        {
            tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
            one = computeReference(room.scene, room.gbuffer, makeQuickSettings(q));
        }
        {
            tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 2);
            two = computeReference(room.scene, room.gbuffer, makeQuickSettings(q));
        }
        SCOPED_TRACE(getQuantityName(q));
        EXPECT_GT(one.stats.rayCount, 0u);
        EXPECT_EQ(one.stats.rayCount, two.stats.rayCount);
        expectIdentical(one, two);
        // The explicit thread-count setting as well.
        ReferenceSettings s = makeQuickSettings(q);
        s.threadCount = 2;
        expectIdentical(one, computeReference(room.scene, room.gbuffer, s));
    }
}

// The occlusion quantities trace a batch's rays as one Embree stream; every sample must be the one
// evaluateOcclusionSample gives alone, for any batch start and length.
TEST(ReferencePipeline, StreamedOcclusionBatchesEqualSingleSamples)
{
    const Room room;
    for (Quantity q : {Quantity::Ao, Quantity::AoUniform, Quantity::Bent, Quantity::Obscurance}) {
        SCOPED_TRACE(getQuantityName(q));
        ReferenceSettings s = makeQuickSettings(q);
        s.radius = 1.5;
        const PreparedReference prepared(room.scene, room.gbuffer, s);
        int pixels = 0, occludedSamples = 0;
        for (std::size_t pixel = 0; pixel < prepared.getActive().size(); pixel += 7) {
            if (!prepared.getActive()[pixel])
                continue;
            ++pixels;
            const std::uint32_t first = std::uint32_t(pixel % 5), count = 45; // crosses a 32-ray chunk
            std::vector<SampleValue> batch(count, SampleValue{});
            const std::uint32_t batchRays = prepared.evaluateBatch(pixel, first, count, batch.data());
            std::uint32_t singleRays = 0;
            for (std::uint32_t i = 0; i < count; ++i) {
                SampleValue one{};
                singleRays += prepared.evaluate(pixel, first + i, one);
                for (int c = 0; c < kMaxChannels; ++c)
                    ASSERT_EQ(batch[i][std::size_t(c)], one[std::size_t(c)]) << pixel << " sample " << first + i;
                occludedSamples += one[q == Quantity::Bent ? 3 : 0] < 1.0 ? 1 : 0;
            }
            EXPECT_EQ(batchRays, singleRays);
        }
        EXPECT_GT(pixels, 20);
        EXPECT_GT(occludedSamples, 0); // the room occludes some rays: hits and misses both compared
    }
}

// A batch of the light quantities traces the point lights' shadow rays from the G-buffer point
// once (the same for every sample); every sample must still be the one evaluateLightSample gives
// alone, and the rays saved exactly the repeats of those.
TEST(ReferencePipeline, LightBatchesShareTheFirstVertexPointLightsAndEqualSingleSamples)
{
    const Room room;
    ASSERT_FALSE(room.scene.pointLights.empty());
    for (Quantity q : {Quantity::Direct, Quantity::Indirect, Quantity::Full}) {
        SCOPED_TRACE(getQuantityName(q));
        const ReferenceSettings s = makeQuickSettings(q);
        const PreparedReference prepared(room.scene, room.gbuffer, s);
        int pixels = 0, litPixels = 0;
        std::uint64_t saved = 0;
        for (std::size_t pixel = 0; pixel < prepared.getActive().size(); pixel += 5) {
            if (!prepared.getActive()[pixel])
                continue;
            ++pixels;
            const std::uint32_t first = std::uint32_t(pixel % 3), count = 40;
            std::vector<SampleValue> batch(count, SampleValue{});
            const std::uint32_t batchRays =
                prepared.evaluateBatch(pixel, first, count, batch.data());
            std::uint32_t singleRays = 0;
            for (std::uint32_t i = 0; i < count; ++i) {
                SampleValue one{};
                singleRays += prepared.evaluate(pixel, first + i, one);
                for (int c = 0; c < kMaxChannels; ++c)
                    ASSERT_EQ(batch[i][std::size_t(c)], one[std::size_t(c)])
                        << pixel << " sample " << first + i;
            }
            ASSERT_LE(batchRays, singleRays);
            // Each sample alone traces the shared rays too: count - 1 repeats of them are saved.
            const std::uint32_t perSample = (singleRays - batchRays) / (count - 1);
            EXPECT_EQ(singleRays - batchRays, perSample * (count - 1));
            EXPECT_LE(perSample, room.scene.pointLights.size());
            if (q == Quantity::Indirect) {
                EXPECT_EQ(batchRays, singleRays); // light at the point itself is not kept
            }
            litPixels += perSample > 0 ? 1 : 0;
            saved += singleRays - batchRays;
        }
        EXPECT_GT(pixels, 20);
        if (q != Quantity::Indirect) {
            EXPECT_GT(litPixels, pixels / 2) << saved; // most of the room faces its light
        }
    }
}

TEST(ReferencePipeline, ProgressiveStopsAtTheTargetOrTheCap)
{
    const Room room;
    ReferenceSettings s = makeQuickSettings(Quantity::Ao);
    s.targetStdErr = 0.02;
    s.targetRelStdErr = 0.0;
    const ReferenceResult r = computeReference(room.scene, room.gbuffer, s);
    int atCap = 0, early = 0;
    std::uint64_t samples = 0;
    for (std::size_t i = 0; i < r.sampleCount.size(); ++i) {
        const std::uint32_t n = r.sampleCount.pixels[i];
        samples += n;
        if (room.gbuffer.materialId.pixels[i] == scene::kNoMaterial) {
            EXPECT_EQ(n, 0u);
            EXPECT_EQ(r.occlusion.pixels[i], 1.0f);
            EXPECT_EQ(r.occlusionStdErr.pixels[i], 0.0f);
            continue;
        }
        EXPECT_EQ(n % 32, 0u);
        EXPECT_GE(n, 32u);
        EXPECT_LE(n, 256u);
        if (n < 256) {
            ++early;
            EXPECT_LE(r.occlusionStdErr.pixels[i], 0.02f); // stopped because it met the target
        } else if (r.occlusionStdErr.pixels[i] > 0.02f) {
            ++atCap;
        }
    }
    EXPECT_GT(early, 0);
    EXPECT_EQ(atCap, r.stats.pixelsAtCap);
    EXPECT_EQ(samples, r.stats.rayCount); // cosine AO: one ray per sample
    EXPECT_LE(r.stats.maxStdErr, 0.2);
    // A tighter target never takes fewer samples for any pixel (same sequence, later stop).
    s.targetStdErr = 0.01;
    const ReferenceResult tighter = computeReference(room.scene, room.gbuffer, s);
    for (std::size_t i = 0; i < r.sampleCount.size(); ++i)
        EXPECT_GE(tighter.sampleCount.pixels[i], r.sampleCount.pixels[i]);
}

TEST(ReferencePipeline, ProgressiveMomentsEqualTwoPassMomentsForAnyBatchSize)
{
    // Whatever the batch size, the running moments (Welford's update) must give the mean and the
    // covariance of the mean of the whole sample set computed in two passes, to rounding. Three
    // correlated channels with a large offset (cancellation-prone for a naive sum of squares), 1000
    // samples, no early stop. Values near 1e4 carry an absolute rounding of about 2e-12, so each
    // deviation of order 1 agrees to about 1e-12 relative; 1e-10 relative on the covariance leaves
    // room for 1000 such terms, 1e-12 on the mean.
    const auto valueOf = [](std::uint32_t i, int c) {
        const double u = std::sin(0.37 * double(i) + 1.3 * c);
        return 1.0e4 + double(c) + (c == 2 ? 0.5 : 1.0) * u + 0.25 * std::cos(0.11 * double(i));
    };
    constexpr std::uint32_t kSamples = 1000;
    std::array<double, kMaxChannels> mean{};
    for (std::uint32_t i = 0; i < kSamples; ++i)
        for (int c = 0; c < 3; ++c)
            mean[c] += valueOf(i, c) / kSamples;
    std::array<double, kMaxChannels * kMaxChannels> covariance{};
    for (std::uint32_t i = 0; i < kSamples; ++i)
        for (int a = 0; a < 3; ++a)
            for (int b = 0; b < 3; ++b)
                covariance[a * kMaxChannels + b] += (valueOf(i, a) - mean[a]) *
                                                    (valueOf(i, b) - mean[b]) /
                                                    (double(kSamples - 1) * kSamples);
    const std::vector<std::uint8_t> active = {1};
    for (int batch : {1, 7, 16, 1000}) {
        ProgressiveRule rule;
        rule.channels = 3;
        rule.batchSize = batch;
        rule.maxSamples = int(kSamples);
        const ProgressiveOutput out = runProgressive(
            1, 1, active, rule,
            [&](std::size_t, std::uint32_t first, std::uint32_t count, SampleValue* values) {
                for (std::uint32_t k = 0; k < count; ++k)
                    for (int c = 0; c < 3; ++c)
                        values[k][c] = valueOf(first + k, c);
                return count;
            });
        const PixelEstimate& p = out.pixels[0];
        EXPECT_EQ(p.samples, kSamples);
        for (int a = 0; a < 3; ++a) {
            EXPECT_NEAR(p.mean[a], mean[a], 1e-12 * std::abs(mean[a])) << "batch " << batch;
            for (int b = 0; b < 3; ++b)
                EXPECT_NEAR(p.covariance[a * kMaxChannels + b], covariance[a * kMaxChannels + b],
                            1e-10 * std::abs(covariance[a * kMaxChannels + a]))
                    << "batch " << batch << " entry " << a << "," << b;
        }
    }
}

TEST(ReferencePipeline, SecondCallIsACacheHitWithIdenticalPixels)
{
    const Room room;
    const std::string dir = test::makeTemporaryFolder("cache");
    ReferenceSettings s = makeQuickSettings(Quantity::Bent);
    s.useCache = true;
    s.cacheDirectory = dir;
    const ReferenceResult first = computeReference(room.scene, room.gbuffer, s);
    EXPECT_FALSE(first.stats.fromCache);
    EXPECT_EQ(first.stats.cacheKey.size(), 32u);
    EXPECT_TRUE(std::filesystem::exists(first.stats.cachePath + "/bent.exr"));
    EXPECT_TRUE(std::filesystem::exists(first.stats.cachePath + "/bent_stderr.exr"));
    EXPECT_TRUE(std::filesystem::exists(first.stats.cachePath + "/bent.json"));

    const ReferenceResult second = computeReference(room.scene, room.gbuffer, s);
    EXPECT_TRUE(second.stats.fromCache);
    EXPECT_EQ(second.stats.cacheKey, first.stats.cacheKey);
    EXPECT_EQ(second.stats.rayCount, first.stats.rayCount);
    EXPECT_EQ(second.stats.seconds, first.stats.seconds);
    expectIdentical(first, second);
    std::printf("    cache: computed in %.3f s, hit %s\n", first.stats.seconds,
                second.stats.cachePath.c_str());

    // What changes the result changes the key; the thread count does not.
    ReferenceSettings other = s;
    other.seed = 1;
    EXPECT_FALSE(computeReference(room.scene, room.gbuffer, other).stats.fromCache);
    other = s;
    other.threadCount = 1;
    EXPECT_TRUE(computeReference(room.scene, room.gbuffer, other).stats.fromCache);
    scene::GBuffer moved = room.gbuffer;
    moved.position.pixels[17].x += 1e-3f;
    EXPECT_NE(computeReferenceCacheKey(room.scene, moved, s), first.stats.cacheKey);
    scene::RenderScene brighter = room.scene;
    brighter.pointLights[0].intensity *= 2.0f;
    EXPECT_NE(computeReferenceCacheKey(brighter, room.gbuffer, s), first.stats.cacheKey);
    std::filesystem::remove_all(dir);
}

TEST(ReferencePipeline, CacheDirectoryFollowsTheEnvironment)
{
    ReferenceSettings s;
    s.cacheDirectory = "/somewhere";
    EXPECT_EQ(getReferenceCacheDirectory(s), "/somewhere");
    s.cacheDirectory.clear();
    const char* cache = std::getenv("RTLAB_CACHE_DIR");
    const std::string savedCache = cache ? cache : "";
    ::setenv("RTLAB_CACHE_DIR", "/tmp/rtlab-cache-test", 1);
    EXPECT_EQ(getReferenceCacheDirectory(s), "/tmp/rtlab-cache-test/reference");
    ::unsetenv("RTLAB_CACHE_DIR");
    const char* home = std::getenv("HOME");
    const std::string savedHome = home ? home : "";
    ::setenv("HOME", "/home/someone", 1);
    EXPECT_EQ(getReferenceCacheDirectory(s), "/home/someone/.cache/rtlab/reference");
    if (home)
        ::setenv("HOME", savedHome.c_str(), 1);
    else
        ::unsetenv("HOME");
    if (!savedCache.empty())
        ::setenv("RTLAB_CACHE_DIR", savedCache.c_str(), 1);
}

TEST(ReferencePipeline, ExrRoundTripIsExact)
{
    const Room room;
    const std::string dir = test::makeTemporaryFolder("exr");
    for (Quantity q : {Quantity::Ao, Quantity::Obscurance, Quantity::Bent, Quantity::Direct}) {
        ReferenceSettings s = makeQuickSettings(q);
        s.maxSamples = 64;
        const ReferenceResult r = computeReference(room.scene, room.gbuffer, s);
        writeReferenceExr(r, dir);
        const std::string name = getQuantityName(q);
        EXPECT_TRUE(std::filesystem::exists(dir + "/" + name + ".exr"));
        EXPECT_TRUE(std::filesystem::exists(dir + "/" + name + "_stderr.exr"));
        const ReferenceResult back = readReferenceExr(dir, q);
        SCOPED_TRACE(name);
        EXPECT_EQ(back.width, r.width);
        EXPECT_EQ(back.height, r.height);
        expectIdentical(r, back);
        EXPECT_EQ(back.settings.radius, s.radius);
        EXPECT_EQ(back.settings.falloff, s.falloff);
        EXPECT_EQ(back.settings.maxSamples, s.maxSamples);
        EXPECT_EQ(back.stats.rayCount, r.stats.rayCount);
        EXPECT_EQ(back.stats.rayEpsilon, r.stats.rayEpsilon);
    }
    // An infinite radius reads back as infinity.
    ReferenceSettings s = makeQuickSettings(Quantity::Ao);
    s.radius = std::numeric_limits<double>::infinity();
    s.maxSamples = 32;
    writeReferenceExr(computeReference(room.scene, room.gbuffer, s), dir);
    EXPECT_TRUE(std::isinf(readReferenceExr(dir, Quantity::Ao).settings.radius));
    EXPECT_THROW(readReferenceExr(dir, Quantity::Full), Error); // never written
    std::filesystem::remove_all(dir);
}

TEST(ReferencePipeline, BadInputIsAClearError)
{
    const Room room;
    const ReferenceSettings s = makeQuickSettings(Quantity::Ao);
    auto expectError = [&](const scene::RenderScene& sc, const scene::GBuffer& g,
                           const ReferenceSettings& settings, const std::string& part) {
        try {
            computeReference(sc, g, settings);
            ADD_FAILURE() << "no error; expected one mentioning '" << part << "'";
        } catch (const Error& e) {
            EXPECT_THAT(e.what(), HasSubstr(part));
        }
    };

    scene::GBuffer g = room.gbuffer;
    g.normal = Image<glm::vec3>(8, 16);
    expectError(room.scene, g, s, "G-buffer image 'normal' is 8x16");
    g = room.gbuffer;
    g.materialId.pixels.pop_back();
    expectError(room.scene, g, s, "'materialId'");
    g = room.gbuffer;
    g.width = 0;
    expectError(room.scene, g, s, "G-buffer is empty");

    expectError(scene::RenderScene{}, room.gbuffer, s, "no triangles");
    scene::RenderScene broken = room.scene;
    broken.triangleMaterial.pop_back();
    expectError(broken, room.gbuffer, s, "triangle materials");
    broken = room.scene;
    broken.indices[4] = 100000;
    expectError(broken, room.gbuffer, s, "index 4");

    ReferenceSettings bad = s;
    bad.quantity = Quantity::Obscurance;
    bad.radius = std::numeric_limits<double>::infinity();
    expectError(room.scene, room.gbuffer, bad, "finite radius");
    bad = s;
    bad.maxSamples = 8;
    expectError(room.scene, room.gbuffer, bad, "maxSamples");
    bad = s;
    bad.radius = -1.0;
    expectError(room.scene, room.gbuffer, bad, "radius");
    EXPECT_THROW(parseQuantity("occlusion"), Error);
    EXPECT_EQ(parseQuantity("ao_uniform"), Quantity::AoUniform);
    for (Quantity q : getAllQuantities())
        EXPECT_EQ(parseQuantity(getQuantityName(q)), q);
}

TEST(ReferencePipeline, ThroughputReportsBothRates)
{
    const Room room;
    ReferenceSettings s = makeQuickSettings(Quantity::Ao);
    const RayThroughput t = measureRayThroughput(room.scene, room.gbuffer, s, 16);
    EXPECT_EQ(t.referenceRays, t.rawRays); // cosine AO: one ray per sample, same rays
    std::uint64_t active = 0;
    const PreparedReference prepared(room.scene, room.gbuffer, s);
    for (std::uint8_t a : prepared.getActive())
        active += a;
    EXPECT_EQ(t.referenceSamples, active * 16);
    EXPECT_EQ(t.referenceRays, t.referenceSamples);
    EXPECT_GT(t.referenceMraysPerSecond, 0.0);
    EXPECT_GT(t.rawIntersectMraysPerSecond, 0.0);
    EXPECT_GT(t.rawOccludedMraysPerSecond, 0.0);
    // The replay traces every ray the estimator traced, once.
    EXPECT_EQ(t.replayRays, t.referenceRays);
    EXPECT_GT(t.replayMraysPerSecond, 0.0);
}

// For a path-traced quantity the estimator's rays (bounces, shadow rays to the lights, sky
// samples) are what the replay traces: as many as the estimator counts, more than one per sample.
TEST(ReferencePipeline, ThroughputReplaysTheEstimatorsOwnRays)
{
    const Room room;
    ReferenceSettings s = makeQuickSettings(Quantity::Full);
    const RayThroughput t = measureRayThroughput(room.scene, room.gbuffer, s, 4, 1);
    EXPECT_EQ(t.replayRays, t.referenceRays);
    EXPECT_GT(t.replayRays, t.rawRays);
    EXPECT_GT(t.replayMraysPerSecond, 0.0);
}

} // namespace
} // namespace rtlab::reference
