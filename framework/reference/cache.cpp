#include "reference/cache.h"

#include "core/error.h"
#include "core/hash.h"
#include "reference/sequences.h"

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <system_error>
#include <thread>

namespace rtlab::reference {

namespace fs = std::filesystem;

namespace {

template <class T> void addImage(Hasher& h, const Image<T>& image)
{
    h.addValue(image.width).addValue(image.height).addValue(image.pixels.size());
    h.addBytes(image.pixels.data(), image.pixels.size() * sizeof(T));
}

} // namespace

std::string computeReferenceCacheKey(const scene::RenderScene& scene, const scene::GBuffer& gbuffer,
                                     const ReferenceSettings& settings)
{
    Hasher h;
    h.add("rtlab reference v1");
    h.add(scene.computeContentHash());

    const scene::Camera& c = gbuffer.camera;
    h.addValue(gbuffer.width).addValue(gbuffer.height).addValue(gbuffer.jitter);
    h.addValue(c.position).addValue(c.target).addValue(c.up).addValue(c.verticalFovDegrees);
    h.addValue(c.nearPlane)
        .addValue(c.farPlane)
        .addValue(gbuffer.view)
        .addValue(gbuffer.projection);
    // The surface points themselves: G-buffers need not come from the camera alone.
    addImage(h, gbuffer.position);
    addImage(h, gbuffer.normal);
    addImage(h, gbuffer.albedo);
    addImage(h, gbuffer.emission);
    addImage(h, gbuffer.materialId);

    const Quantity q = settings.quantity;
    h.add(getQuantityName(q));
    const bool occlusion = q == Quantity::Ao || q == Quantity::AoUniform ||
                           q == Quantity::Obscurance || q == Quantity::Bent;
    if (occlusion)
        h.add("radius").addValue(settings.radius);
    if (q == Quantity::Obscurance)
        h.add("falloff").add(getFalloffName(settings.falloff));
    if (q == Quantity::Indirect || q == Quantity::Full)
        h.add("bounces").addValue(settings.bounces);
    h.addValue(settings.targetStdErr).addValue(settings.targetRelStdErr);
    h.addValue(settings.batchSize).addValue(settings.maxSamples).addValue(settings.seed);
    h.addValue(settings.rayEpsilonScale);
    return h.hexDigest();
}

std::string getReferenceCacheDirectory(const ReferenceSettings& settings)
{
    if (!settings.cacheDirectory.empty())
        return settings.cacheDirectory;
    if (const char* dir = std::getenv("RTLAB_CACHE_DIR"); dir && *dir)
        return (fs::path(dir) / "reference").string();
    if (const char* home = std::getenv("HOME"); home && *home)
        return (fs::path(home) / ".cache" / "rtlab" / "reference").string();
    return (fs::temp_directory_path() / "rtlab" / "reference").string();
}

std::string getCacheEntryPath(const std::string& root, const std::string& key)
{
    return (fs::path(root) / key).string();
}

std::optional<ReferenceResult> loadCachedReference(const std::string& root, const std::string& key,
                                                   Quantity quantity, int width, int height)
{
    const std::string entry = getCacheEntryPath(root, key);
    std::error_code ec;
    if (!fs::is_directory(entry, ec))
        return std::nullopt;
    try {
        ReferenceResult r = readReferenceExr(entry, quantity);
        if (r.width != width || r.height != height || r.stats.cacheKey != key)
            return std::nullopt;
        return r;
    } catch (const Error&) {
        return std::nullopt; // unreadable: recompute and overwrite
    }
}

std::string storeCachedReference(const std::string& root, const std::string& key,
                                 const ReferenceResult& result)
{
    static std::atomic<std::uint64_t> counter{0};
    const std::string entry = getCacheEntryPath(root, key);
    const std::uint64_t unique = mixBits64(
        std::uint64_t(std::chrono::steady_clock::now().time_since_epoch().count()) ^
        (counter.fetch_add(1) << 48) ^ std::hash<std::thread::id>{}(std::this_thread::get_id()));
    const fs::path temporary = fs::path(root) / (key + ".tmp-" + std::to_string(unique));
    writeReferenceExr(result, temporary.string());

    std::error_code ec;
    fs::remove_all(entry, ec); // a stale or unreadable entry of the same key
    fs::rename(temporary, entry, ec);
    if (ec) {
        fs::remove_all(temporary, ec);
        // Another process stored the same key first: that entry is as good as ours.
        if (!fs::is_directory(entry, ec))
            throw Error("reference: cannot store the cache entry '" + entry + "'");
    }
    return entry;
}

} // namespace rtlab::reference
