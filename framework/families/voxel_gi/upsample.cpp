#include "families/voxel_gi/upsample.h"

#include "core/error.h"
#include "families/voxel_gi/cone_tracing.h"

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <string>

namespace rtlab::voxelgi {

ReducedGBuffer reduceGBuffer(const scene::GBuffer& full, int factor)
{
    if (factor < 1 || factor > 16)
        throw Error("reduced gather: factor must be in [1, 16], found " + std::to_string(factor));
    ReducedGBuffer r;
    r.factor = factor;
    const int lw = (full.width + factor - 1) / factor, lh = (full.height + factor - 1) / factor;
    scene::GBuffer& g = r.gbuffer;
    g.width = lw;
    g.height = lh;
    g.camera = full.camera;
    g.jitter = full.jitter;
    g.view = full.view;
    g.projection = full.projection;
    g.depth = Image<float>(lw, lh, std::numeric_limits<float>::infinity());
    g.position = Image<glm::vec3>(lw, lh, glm::vec3(0.0f));
    g.normal = Image<glm::vec3>(lw, lh, glm::vec3(0.0f));
    g.albedo = Image<glm::vec3>(lw, lh, glm::vec3(0.0f));
    g.emission = Image<glm::vec3>(lw, lh, glm::vec3(0.0f));
    g.materialId = Image<std::uint32_t>(lw, lh, scene::kNoMaterial);
    r.representative.assign(std::size_t(lw) * std::size_t(lh), -1);
    for (int by = 0; by < lh; ++by)
        for (int bx = 0; bx < lw; ++bx) {
            int chosen = -1;
            const int cx = std::min(bx * factor + factor / 2, full.width - 1);
            const int cy = std::min(by * factor + factor / 2, full.height - 1);
            if (full.hasSurface(cx, cy))
                chosen = cy * full.width + cx;
            for (int y = by * factor; chosen < 0 && y < std::min(full.height, (by + 1) * factor); ++y)
                for (int x = bx * factor; chosen < 0 && x < std::min(full.width, (bx + 1) * factor); ++x)
                    if (full.hasSurface(x, y))
                        chosen = y * full.width + x;
            r.representative[std::size_t(by) * std::size_t(lw) + std::size_t(bx)] = chosen;
            if (chosen < 0)
                continue;
            const int x = chosen % full.width, y = chosen / full.width;
            g.depth.at(bx, by) = full.depth.at(x, y);
            g.position.at(bx, by) = full.position.at(x, y);
            g.normal.at(bx, by) = full.normal.at(x, y);
            if (!full.albedo.pixels.empty())
                g.albedo.at(bx, by) = full.albedo.at(x, y);
            if (!full.emission.pixels.empty())
                g.emission.at(bx, by) = full.emission.at(x, y);
            g.materialId.at(bx, by) = full.materialId.at(x, y);
        }
    return r;
}

std::vector<Image<float>> reduceConeImages(const std::vector<Image<float>>* full,
                                           const ReducedGBuffer& reduced)
{
    std::vector<Image<float>> out;
    if (full == nullptr)
        return out;
    const int lw = reduced.gbuffer.width, lh = reduced.gbuffer.height;
    for (const Image<float>& image : *full) {
        Image<float> low(lw, lh, 1.0f);
        for (std::size_t i = 0; i < reduced.representative.size(); ++i)
            if (const int r = reduced.representative[i]; r >= 0)
                low.pixels[i] = image.pixels[std::size_t(r)];
        out.push_back(std::move(low));
    }
    return out;
}

namespace {

// The low-resolution samples a full-resolution pixel blends and their weights (summing to 1):
// the four around it, bilinear times geometric similarity; when all four fail, the most similar
// of the 3 x 3 around (else the nearest with a surface). Returns how many (0 for no surface).
int findUpsampleSamples(const ReducedGBuffer& reduced, const scene::GBuffer& full, int x, int y,
                        int samples[4], float weights[4])
{
    if (!full.hasSurface(x, y))
        return 0;
    const int f = reduced.factor;
    const int lw = reduced.gbuffer.width, lh = reduced.gbuffer.height;
    const glm::vec3 p = full.position.at(x, y), n = full.normal.at(x, y);
    const float d = std::isfinite(full.depth.at(x, y)) ? full.depth.at(x, y) : 1.0f;
    // Geometric similarity of low-resolution sample s to the pixel: distance of s from the
    // pixel's tangent plane against 2 % of the view depth, and the normals' agreement (cos^8).
    // The reduced G-buffer holds each representative's position and normal (reduceGBuffer
    // copies them), so they are read there, contiguously and without dividing the pixel index.
    const auto similarity = [&](int s) {
        if (reduced.representative[std::size_t(s)] < 0)
            return 0.0f;
        const float plane =
            std::abs(glm::dot(n, reduced.gbuffer.position.pixels[std::size_t(s)] - p)) /
            std::max(0.02f * d, 1e-6f);
        const float c = std::max(0.0f, glm::dot(n, reduced.gbuffer.normal.pixels[std::size_t(s)]));
        const float c2 = c * c, c4 = c2 * c2;
        // expf is exactly 0 below -103.98 (under the smallest denormal); libm reaches that
        // through its slow underflow path, a tenth of the combine's time on a scene of
        // silhouettes, so it is skipped there (the same value).
        const float q = plane * plane;
        return (q < 104.0f ? std::exp(-q) : 0.0f) * c4 * c4;
    };
    if (f == 1) {
        samples[0] = y * lw + x;
        weights[0] = 1.0f;
        return 1;
    }
    const float u = (x + 0.5f) / float(f) - 0.5f, v = (y + 0.5f) / float(f) - 0.5f;
    const int i0 = int(std::floor(u)), j0 = int(std::floor(v));
    const float fu = u - float(i0), fv = v - float(j0);
    int count = 0;
    float total = 0.0f;
    for (int dj = 0; dj <= 1; ++dj)
        for (int di = 0; di <= 1; ++di) {
            const int i = std::clamp(i0 + di, 0, lw - 1), j = std::clamp(j0 + dj, 0, lh - 1);
            const float bilinear = (di ? fu : 1.0f - fu) * (dj ? fv : 1.0f - fv);
            const int s = j * lw + i;
            const float w = bilinear * similarity(s);
            if (w <= 0.0f)
                continue;
            samples[count] = s;
            weights[count] = w;
            total += w;
            ++count;
        }
    if (total > 1e-6f) {
        for (int k = 0; k < count; ++k)
            weights[k] /= total;
        return count;
    }
    const int ci = std::clamp(x / f, 0, lw - 1), cj = std::clamp(y / f, 0, lh - 1);
    float best = -1.0f;
    int bestSample = -1;
    for (int j = std::max(0, cj - 1); j <= std::min(lh - 1, cj + 1); ++j)
        for (int i = std::max(0, ci - 1); i <= std::min(lw - 1, ci + 1); ++i) {
            const int s = j * lw + i;
            if (reduced.representative[std::size_t(s)] < 0)
                continue;
            const float w = similarity(s) - 1e-3f * float(std::abs(i - ci) + std::abs(j - cj));
            if (w > best) {
                best = w;
                bestSample = s;
            }
        }
    if (bestSample < 0)
        return 0;
    samples[0] = bestSample;
    weights[0] = 1.0f;
    return 1;
}

} // namespace

Image<glm::vec3> upsampleIrradiance(const Image<glm::vec3>& low, const ReducedGBuffer& reduced,
                                    const scene::GBuffer& full)
{
    if (reduced.factor == 1)
        return low;
    const int lw = reduced.gbuffer.width, lh = reduced.gbuffer.height;
    if (low.width != lw || low.height != lh)
        throw Error("reduced gather: irradiance of " + std::to_string(low.width) + "x" +
                    std::to_string(low.height) + " for a reduced G-buffer of " +
                    std::to_string(lw) + "x" + std::to_string(lh));
    Image<glm::vec3> out(full.width, full.height, glm::vec3(0.0f));
    for (int y = 0; y < full.height; ++y)
        for (int x = 0; x < full.width; ++x) {
            int samples[4];
            float weights[4];
            const int n = findUpsampleSamples(reduced, full, x, y, samples, weights);
            glm::vec3 sum(0.0f);
            for (int k = 0; k < n; ++k)
                sum += weights[k] * low.pixels[std::size_t(samples[k])];
            out.at(x, y) = sum;
        }
    return out;
}

namespace {

// A cone's half angle with its cosine and sine, computed once for many capsule tests.
struct ConeAngle {
    double half, cosHalf, sinHalf;
};

// A capsule as seen from one point, for its tests against the point's cones: the segment's start
// relative to the point (w0 = a - p), its direction u = b - a, and what every cone's test reuses.
struct CapsuleFromPoint {
    glm::dvec3 w0, u;
    double uu, inverseLength2, uw, radius;
};

CapsuleFromPoint seeCapsule(const glm::dvec3& p, const glm::dvec3& a, const glm::dvec3& u,
                            double radius)
{
    CapsuleFromPoint c;
    c.w0 = a - p;
    c.u = u;
    c.uu = glm::dot(c.u, c.u);
    c.inverseLength2 = c.uu > 0.0 ? 1.0 / c.uu : 0.0;
    c.uw = glm::dot(c.u, c.w0);
    c.radius = radius;
    return c;
}

// On or inside the capsule (within 5 % of its radius): its own character's surface is not
// occluded by it.
bool isOnCapsule(const CapsuleFromPoint& c)
{
    const glm::dvec3 fromSegment = c.w0 + std::clamp(-c.uw * c.inverseLength2, 0.0, 1.0) * c.u;
    return glm::dot(fromSegment, fromSegment) <= (1.05 * c.radius) * (1.05 * c.radius);
}

// The share of the cone (axis dir, from the point the capsule was seen from) that the capsule
// hides: the sphere of the capsule's radius at the point of its segment nearest the cone's axis,
// as a spherical cap against the cone's cap (Oat and Sander 2007, "Ambient aperture lighting").
// Every point below is relative to the point: the segment runs from w0 to w0 + u.
double occludeCone(const CapsuleFromPoint& c, const glm::dvec3& dir, const ConeAngle& cone)
{
    const double r = c.radius;
    // The point of the segment nearest the cone's axis (closest points of a segment and a ray):
    // s on the segment, t on the ray, then the segment's point nearest the ray's point at t.
    const double ud = glm::dot(c.u, dir), dw = glm::dot(dir, c.w0);
    const double denom = c.uu - ud * ud;
    const double s = denom > 1e-12 * std::max(c.uu, 1e-300)
                         ? std::clamp((ud * dw - c.uw) / denom, 0.0, 1.0)
                         : 0.0;
    const double t = std::max(0.0, dw + s * ud);
    const double along = std::clamp((t * ud - c.uw) * c.inverseLength2, 0.0, 1.0);
    const glm::dvec3 toCentre = c.w0 + along * c.u;
    const double distance = std::sqrt(glm::dot(toCentre, toCentre));
    if (!(distance > r))
        return 0.0;
    // Disjoint caps (the angle between them at least the sum of their half angles) are tested on
    // cosines first, with no inverse trigonometric function.
    const double sinCap = std::min(1.0, r / distance), cosCap = std::sqrt(1.0 - sinCap * sinCap);
    const double cosOuter = cone.cosHalf * cosCap - cone.sinHalf * sinCap;
    const double cosBetween = std::clamp(glm::dot(toCentre, dir) / distance, -1.0, 1.0);
    if (cosBetween < cosOuter - 1e-9) // margin: rounding of the two paths
        return 0.0;
    const double coneSolid = 1.0 - cone.cosHalf; // solid angles / 2 pi
    // The smaller cap's solid angle: 1 - cos(min(half, cap)) = 1 - max(cos half, cos cap).
    const double smaller = 1.0 - std::max(cone.cosHalf, cosCap);
    // One cap inside the other (the angle between them at most the difference of their half
    // angles): the whole smaller cap is hidden; tested on cosines too.
    const double cosInner = cone.cosHalf * cosCap + cone.sinHalf * sinCap;
    if (cosBetween >= cosInner)
        return std::clamp(smaller / coneSolid, 0.0, 1.0);
    // Between the two: Oat and Sander's smoothstep in the angle between the caps.
    const double capAngle = std::asin(sinCap);
    const double between = std::acos(cosBetween);
    const double outer = cone.half + capAngle, inner = std::abs(cone.half - capAngle);
    if (between >= outer)
        return 0.0;
    double share = 1.0;
    if (between > inner) {
        const double x = std::clamp(1.0 - (between - inner) / (outer - inner), 0.0, 1.0);
        share = x * x * (3.0 - 2.0 * x);
    }
    return std::clamp(smaller * share / coneSolid, 0.0, 1.0);
}

// The characters' capsules as the combine tests them: per capsule, once, its segment, the sphere
// around it and the squared distances within which it is near a point (40 radii from the
// segment: a capsule farther away hides less than 0.25 % of a cone; from the sphere's centre, a
// bound of that); per point, the capsules near it, each seen from the point once for all its
// cones.
class CapsuleOccluders {
public:
    CapsuleOccluders(const std::vector<scene::PosedCapsule>* capsules, const ConeAngle& angle)
        : mAngle(angle)
    {
        if (capsules == nullptr)
            return;
        for (const scene::PosedCapsule& c : *capsules) {
            Bounds b;
            b.a = glm::dvec3(c.capsule.a);
            b.u = glm::dvec3(c.capsule.b) - b.a;
            b.centre = b.a + 0.5 * b.u;
            const double uu = glm::dot(b.u, b.u);
            b.inverseLength2 = uu > 0.0 ? 1.0 / uu : 0.0;
            b.radius = double(c.capsule.radius);
            b.bound = 0.5 * std::sqrt(uu) + b.radius;
            b.near2 = (40.0 * b.radius) * (40.0 * b.radius);
            b.reach2 =
                (0.5 * std::sqrt(uu) + 40.0 * b.radius) * (0.5 * std::sqrt(uu) + 40.0 * b.radius);
            mBounds.push_back(b);
        }
    }

    bool empty() const { return mBounds.empty(); }

    //! A capsule near a point, with the cosine below which a cone direction's angle to its
    //! bounding sphere's centre is too wide for the cone to touch it (-2: no such bound).
    struct Near {
        CapsuleFromPoint seen;
        glm::dvec3 towardCentre;
        double cosLimit;
    };

    //! The capsules near p that can hide part of its cones; none that p lies on (isOnCapsule).
    void collect(const glm::dvec3& p, std::vector<Near>& near) const
    {
        near.clear();
        for (const Bounds& c : mBounds) {
            const glm::dvec3 toCentre = c.centre - p;
            const double d2 = glm::dot(toCentre, toCentre);
            if (d2 >= c.reach2)
                continue; // farther than 40 radii from any point of the segment
            Near entry{seeCapsule(p, c.a, c.u, c.radius), glm::dvec3(0.0), -2.0};
            const glm::dvec3 fromSegment =
                entry.seen.w0 + std::clamp(-entry.seen.uw * c.inverseLength2, 0.0, 1.0) * c.u;
            if (glm::dot(fromSegment, fromSegment) >= c.near2 || isOnCapsule(entry.seen))
                continue;
            // The sphere around the whole capsule: a cone whose axis is more than the cone's half
            // angle plus the sphere's angular radius away from the sphere's centre misses every
            // sphere occludeCone places on the segment, so its occlusion is exactly 0.
            if (d2 > c.bound * c.bound) {
                const double distance = std::sqrt(d2);
                const double sinB = c.bound / distance, cosB = std::sqrt(1.0 - sinB * sinB);
                entry.towardCentre = toCentre / distance;
                entry.cosLimit =
                    mAngle.cosHalf * cosB - mAngle.sinHalf * sinB; // cos(half angle + asin(sinB))
            }
            near.push_back(entry);
        }
    }

    //! The share of the cone along dir that the near capsules leave open (their product).
    double visibility(const std::vector<Near>& near, const glm::dvec3& dir) const
    {
        double visible = 1.0;
        for (const Near& c : near) {
            // 1e-9 in cosine keeps rounding from culling a cone that grazes the sphere.
            if (glm::dot(c.towardCentre, dir) < c.cosLimit - 1e-9)
                continue;
            visible *= 1.0 - occludeCone(c.seen, dir, mAngle);
        }
        return visible;
    }

private:
    struct Bounds {
        glm::dvec3 a, u, centre;
        double inverseLength2, radius, bound, near2, reach2;
    };
    std::vector<Bounds> mBounds;
    ConeAngle mAngle;
};

} // namespace

double computeCapsuleConeOcclusion(const glm::dvec3& p, const glm::dvec3& dir, double coneHalfAngle,
                                   const glm::vec3& a, const glm::vec3& b, float radius)
{
    const CapsuleFromPoint c =
        seeCapsule(p, glm::dvec3(a), glm::dvec3(b) - glm::dvec3(a), double(radius));
    if (isOnCapsule(c))
        return 0.0;
    return occludeCone(c, dir, {coneHalfAngle, std::cos(coneHalfAngle), std::sin(coneHalfAngle)});
}

Image<glm::vec3> combineCones(const ConeCombineInputs& in)
{
    if (in.capsuleResolution == CapsuleResolution::Traced && in.capsules != nullptr &&
        in.coneRadiance != nullptr) {
        std::vector<glm::vec3> occluded = *in.coneRadiance;
        occludeTracedCones(in.reduced->gbuffer, occluded, *in.capsules, in.coneHalfAngle);
        ConeCombineInputs rest = in;
        rest.coneRadiance = &occluded;
        rest.capsules = nullptr;
        return combineCones(rest);
    }
    const scene::GBuffer& full = *in.full;
    const ReducedGBuffer& reduced = *in.reduced;
    const std::size_t lowPixels = std::size_t(reduced.gbuffer.width) * std::size_t(reduced.gbuffer.height);
    if (in.coneRadiance->size() != lowPixels * kConeCount)
        throw Error("cone combine: " + std::to_string(in.coneRadiance->size()) +
                    " cone radiances for " + std::to_string(lowPixels) + " pixels x 16 cones");
    const bool useVisibility =
        in.visibility != nullptr && in.visibility->size() == std::size_t(kConeCount);
    ConeSet cones;
    cones.directions = scene::getConeDirections();
    cones.halfAngle = in.coneHalfAngle;
    cones.tanHalfAngle = std::tan(in.coneHalfAngle);
    const ConeAngle angle{in.coneHalfAngle, std::cos(in.coneHalfAngle), std::sin(in.coneHalfAngle)};
    const CapsuleOccluders occluders(in.capsules, angle);
    Image<glm::vec3> out(full.width, full.height, glm::vec3(0.0f));
    tbb::parallel_for(0, full.height, [&](int y) {
        std::vector<CapsuleOccluders::Near> near;
        for (int x = 0; x < full.width; ++x) {
            int samples[4];
            float weights[4];
            const int count = findUpsampleSamples(reduced, full, x, y, samples, weights);
            if (count == 0)
                continue;
            const glm::dvec3 p(full.position.at(x, y)), n(full.normal.at(x, y));
            if (glm::dot(n, n) < 0.5)
                continue;
            occluders.collect(p, near);
            const auto w = computeIrradianceWeights(cones, n);
            // Each cone's radiance upsampled: the samples' 16 cones are contiguous, so they are
            // read sample by sample (the same sums, in the same order, per cone).
            std::array<glm::dvec3, kConeCount> upsampled{};
            for (int s = 0; s < count; ++s) {
                const glm::vec3* row =
                    in.coneRadiance->data() + std::size_t(samples[s]) * kConeCount;
                const double ws = double(weights[s]);
                for (int k = 0; k < kConeCount; ++k)
                    if (w[std::size_t(k)] != 0.0)
                        upsampled[std::size_t(k)] += ws * glm::dvec3(row[k]);
            }
            glm::dvec3 e(0.0);
            for (int k = 0; k < kConeCount; ++k) {
                if (w[std::size_t(k)] == 0.0)
                    continue;
                const glm::dvec3& radiance = upsampled[std::size_t(k)];
                double visible = 1.0;
                if (useVisibility)
                    visible = std::clamp(double((*in.visibility)[std::size_t(k)].at(x, y)), 0.0, 1.0);
                if (!near.empty())
                    visible *= occluders.visibility(near, cones.directions[std::size_t(k)]);
                e += w[std::size_t(k)] * visible * radiance;
            }
            out.at(x, y) = glm::max(glm::vec3(e), glm::vec3(0.0f));
        }
    });
    return out;
}

void occludeTracedCones(const scene::GBuffer& traced, std::vector<glm::vec3>& coneRadiance,
                        const std::vector<scene::PosedCapsule>& capsules, double coneHalfAngle)
{
    const std::size_t pixels = std::size_t(traced.width) * std::size_t(traced.height);
    if (coneRadiance.size() != pixels * kConeCount)
        throw Error("capsule occlusion: " + std::to_string(coneRadiance.size()) +
                    " cone radiances for " + std::to_string(pixels) + " pixels x 16 cones");
    const CapsuleOccluders occluders(
        &capsules, {coneHalfAngle, std::cos(coneHalfAngle), std::sin(coneHalfAngle)});
    if (occluders.empty())
        return;
    const std::array<glm::dvec3, kConeCount>& directions = scene::getConeDirections();
    tbb::parallel_for(0, traced.height, [&](int y) {
        std::vector<CapsuleOccluders::Near> near;
        for (int x = 0; x < traced.width; ++x) {
            if (glm::dot(traced.normal.at(x, y), traced.normal.at(x, y)) < 0.5f)
                continue; // no surface: the combine reads nothing here
            occluders.collect(glm::dvec3(traced.position.at(x, y)), near);
            if (near.empty())
                continue;
            glm::vec3* row =
                coneRadiance.data() +
                (std::size_t(y) * std::size_t(traced.width) + std::size_t(x)) * kConeCount;
            for (int k = 0; k < kConeCount; ++k)
                if (row[k] != glm::vec3(0.0f))
                    row[k] *= float(occluders.visibility(near, directions[std::size_t(k)]));
        }
    });
}

Image<glm::vec3> gatherConesReduced(
    const scene::GBuffer& full, int traceStep, double coneHalfAngle,
    const std::vector<Image<float>>* visibility, const std::vector<scene::PosedCapsule>* capsules,
    const std::function<void(const scene::GBuffer&, std::vector<glm::vec3>&, std::vector<glm::vec3>*)>&
        traceCones,
    double* combineMs, CapsuleResolution capsuleResolution, ConeSkyTrace* sky)
{
    using Clock = std::chrono::steady_clock;
    const auto start = Clock::now();
    ReducedGBuffer reduced = reduceGBuffer(full, traceStep);
    const auto reducedAt = Clock::now();
    std::vector<glm::vec3> cones;
    if (sky != nullptr)
        sky->cones.clear();
    traceCones(reduced.gbuffer, cones, sky != nullptr ? &sky->cones : nullptr);
    const auto tracedAt = Clock::now();
    // The capsules at the traced pixels in place (combineCones would copy the cones for them).
    const bool capsulesTraced =
        capsuleResolution == CapsuleResolution::Traced && capsules != nullptr;
    if (capsulesTraced)
        occludeTracedCones(reduced.gbuffer, cones, *capsules, coneHalfAngle);
    // The sky's cones wait for the frame's compose (combineConeSky), which may not need them.
    const bool keepSky = sky != nullptr && !sky->cones.empty();
    if (keepSky && capsulesTraced)
        occludeTracedCones(reduced.gbuffer, sky->cones, *capsules, coneHalfAngle);
    ConeCombineInputs combine;
    combine.coneRadiance = &cones;
    combine.reduced = &reduced;
    combine.full = &full;
    combine.visibility = visibility;
    combine.capsules = capsulesTraced ? nullptr : capsules;
    combine.coneHalfAngle = coneHalfAngle;
    Image<glm::vec3> irradiance = combineCones(combine);
    if (combineMs != nullptr)
        *combineMs = std::chrono::duration<double, std::milli>((reducedAt - start) + (Clock::now() - tracedAt)).count();
    if (keepSky) {
        sky->reduced = std::move(reduced);
        sky->capsulesApplied = capsulesTraced;
    }
    return irradiance;
}

void keepConeSky(ConeSkyTrace& sky, const scene::GBuffer& full, int traceStep, double coneHalfAngle,
                 const std::vector<scene::PosedCapsule>* capsules, CapsuleResolution capsuleResolution)
{
    sky.reduced = reduceGBuffer(full, traceStep);
    sky.capsulesApplied = capsuleResolution == CapsuleResolution::Traced && capsules != nullptr;
    if (sky.capsulesApplied && !sky.cones.empty())
        occludeTracedCones(sky.reduced.gbuffer, sky.cones, *capsules, coneHalfAngle);
}

Image<glm::vec3> combineConeSky(const ConeSkyTrace& sky, const scene::GBuffer& full, double coneHalfAngle,
                                const std::vector<Image<float>>* visibility,
                                const std::vector<scene::PosedCapsule>* capsules)
{
    if (!sky.isValid())
        throw Error("cone sky: no cones traced in the last gather (" + std::to_string(sky.cones.size()) +
                    " cone values for a " + std::to_string(sky.reduced.gbuffer.width) + "x" +
                    std::to_string(sky.reduced.gbuffer.height) + " traced G-buffer)");
    const int factor = sky.reduced.factor;
    if (full.width == 0 || (full.width + factor - 1) / factor != sky.reduced.gbuffer.width ||
        (full.height + factor - 1) / factor != sky.reduced.gbuffer.height)
        throw Error("cone sky: traced at " + std::to_string(sky.reduced.gbuffer.width) + "x" +
                    std::to_string(sky.reduced.gbuffer.height) + ", not one pixel per " +
                    std::to_string(factor) + "^2 block of the " + std::to_string(full.width) + "x" +
                    std::to_string(full.height) + " G-buffer");
    ConeCombineInputs combine;
    combine.coneRadiance = &sky.cones;
    combine.reduced = &sky.reduced;
    combine.full = &full;
    combine.visibility = visibility;
    combine.capsules = sky.capsulesApplied ? nullptr : capsules;
    combine.coneHalfAngle = coneHalfAngle;
    return combineCones(combine);
}

Image<glm::vec3> traceRaysReduced(const scene::GBuffer& full, int traceStep,
                                  const std::function<void(const scene::GBuffer&, Image<glm::vec3>&)>& traceRays)
{
    const ReducedGBuffer reduced = reduceGBuffer(full, traceStep);
    Image<glm::vec3> low;
    traceRays(reduced.gbuffer, low);
    return upsampleIrradiance(low, reduced, full);
}

} // namespace rtlab::voxelgi
