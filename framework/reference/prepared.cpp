#include "reference/prepared.h"

#include "core/error.h"

#include <glm/geometric.hpp>

#include <array>
#include <cmath>
#include <string>

namespace rtlab::reference {

namespace {

template <class T>
void checkImageSize(const Image<T>& image, const scene::GBuffer& g, const char* name)
{
    if (image.width != g.width || image.height != g.height ||
        image.pixels.size() != std::size_t(g.width) * std::size_t(g.height))
        throw Error(std::string("reference: G-buffer image '") + name + "' is " +
                    std::to_string(image.width) + "x" + std::to_string(image.height) + " (" +
                    std::to_string(image.pixels.size()) + " pixels) but the G-buffer is " +
                    std::to_string(g.width) + "x" + std::to_string(g.height));
}

bool isFinite(const glm::vec3& v)
{
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

} // namespace

void validateSettings(const ReferenceSettings& s)
{
    auto fail = [](const std::string& what) { throw Error("reference: " + what); };
    if (!(s.radius > 0.0))
        fail("radius must be > 0 (infinity for unlimited), got " + std::to_string(s.radius));
    if (s.quantity == Quantity::Obscurance && !std::isfinite(s.radius))
        fail("obscurance needs a finite radius: its falloff is a function of distance / radius");
    if (s.bounces < -1)
        fail("bounces must be >= 0, or -1 for unlimited, got " + std::to_string(s.bounces));
    if (!(s.targetStdErr >= 0.0) || !(s.targetRelStdErr >= 0.0))
        fail("targetStdErr and targetRelStdErr must be >= 0");
    if (s.batchSize < 1)
        fail("batchSize must be >= 1, got " + std::to_string(s.batchSize));
    if (s.maxSamples < s.batchSize)
        fail("maxSamples (" + std::to_string(s.maxSamples) + ") must be >= batchSize (" +
             std::to_string(s.batchSize) + ")");
    if (s.threadCount < 0)
        fail("threadCount must be >= 0 (0 = all), got " + std::to_string(s.threadCount));
    if (!(s.rayEpsilonScale > 0.0 && s.rayEpsilonScale < 0.01))
        fail("rayEpsilonScale must be in (0, 0.01), got " + std::to_string(s.rayEpsilonScale));
}

void validateGBuffer(const scene::GBuffer& g)
{
    if (g.width <= 0 || g.height <= 0)
        throw Error("reference: the G-buffer is empty (" + std::to_string(g.width) + "x" +
                    std::to_string(g.height) + ")");
    checkImageSize(g.position, g, "position");
    checkImageSize(g.normal, g, "normal");
    checkImageSize(g.albedo, g, "albedo");
    checkImageSize(g.emission, g, "emission");
    checkImageSize(g.materialId, g, "materialId");
    for (int y = 0; y < g.height; ++y) {
        for (int x = 0; x < g.width; ++x) {
            if (!g.hasSurface(x, y))
                continue;
            const glm::vec3& n = g.normal.at(x, y);
            if (!isFinite(g.position.at(x, y)) || !isFinite(n) || !(glm::length(n) > 0.0f) ||
                !isFinite(g.albedo.at(x, y)) || !isFinite(g.emission.at(x, y)))
                throw Error("reference: G-buffer pixel (" + std::to_string(x) + ", " +
                            std::to_string(y) +
                            ") has a surface but a non-finite position, albedo or emission, "
                            "or a zero normal");
        }
    }
}

PreparedReference::PreparedReference(const scene::RenderScene& scene, const scene::GBuffer& gbuffer,
                                     const ReferenceSettings& settings)
    : mSettings((validateSettings(settings), validateGBuffer(gbuffer), settings)), mEmbree(scene),
      mLights(scene)
{
    mContext.embree = &mEmbree;
    mContext.lights = &mLights;
    mContext.quantity = settings.quantity;
    mContext.radius = settings.radius;
    mContext.falloff = settings.falloff;
    mContext.bounces = settings.bounces;
    mContext.rayEpsilon = settings.rayEpsilonScale * mEmbree.getSceneScale();

    const std::size_t pixels = std::size_t(gbuffer.width) * std::size_t(gbuffer.height);
    mActive.assign(pixels, 0);
    mPoints.resize(pixels);
    for (std::size_t i = 0; i < pixels; ++i) {
        if (gbuffer.materialId.pixels[i] == scene::kNoMaterial)
            continue;
        mActive[i] = 1;
        mPoints[i].position = glm::dvec3(gbuffer.position.pixels[i]);
        mPoints[i].normal = glm::normalize(glm::dvec3(gbuffer.normal.pixels[i]));
    }
}

std::uint32_t PreparedReference::evaluate(std::size_t pixel, std::uint32_t index,
                                          SampleValue& value) const
{
    const PixelSequence sequence(mSettings.seed, pixel);
    switch (mContext.quantity) {
    case Quantity::Direct:
    case Quantity::Indirect:
    case Quantity::Full:
        return evaluateLightSample(mContext, mPoints[pixel], sequence, index, value);
    default:
        return evaluateOcclusionSample(mContext, mPoints[pixel], sequence, index, value);
    }
}

std::uint32_t PreparedReference::evaluateBatch(std::size_t pixel, std::uint32_t first, std::uint32_t count,
                                               SampleValue* values) const
{
    const PixelSequence sequence(mSettings.seed, pixel);
    switch (mContext.quantity) {
    case Quantity::Direct:
    case Quantity::Indirect:
    case Quantity::Full: {
        // The first vertices' stream hashes once for the batch, not once per sample.
        std::array<SobolStream, kLightStreamsPerBatch> streams;
        for (std::uint32_t p = 0; p < kLightStreamsPerBatch; ++p)
            streams[p] = sequence.getStream(p);
        // The point lights' shadow rays from the G-buffer point are the same for every sample:
        // traced once for the batch.
        glm::dvec3 pointLights(0.0);
        bool shared = false;
        std::uint32_t rays =
            evaluateFirstVertexPointLights(mContext, mPoints[pixel], sequence, pointLights, shared);
        for (std::uint32_t i = 0; i < count; ++i)
            rays += evaluateLightSample(mContext, mPoints[pixel], sequence, first + i, values[i],
                                        streams.data(), kLightStreamsPerBatch,
                                        shared ? &pointLights : nullptr);
        return rays;
    }
    default:
        return evaluateOcclusionBatch(mContext, mPoints[pixel], sequence, first, count, values);
    }
}

} // namespace rtlab::reference
