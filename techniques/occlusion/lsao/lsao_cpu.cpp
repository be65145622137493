#include "lsao_cpu.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <utility>

namespace rtlab::occlusion::lsao {
namespace {

//! Linear depth of `pixel`, or 0 for sky, invalid depth or outside the image.
float loadDepth(const Image<float>& depth, glm::ivec2 pixel)
{
    if (pixel.x < 0 || pixel.y < 0 || pixel.x >= depth.width || pixel.y >= depth.height)
        return 0.0f;
    const float z = depth.at(pixel.x, pixel.y);
    return z > 0.0f && z < std::numeric_limits<float>::infinity() ? z : 0.0f;
}

struct GatherContext {
    const Layout& layout;
    const plugin::ScreenProjection& projection;
    const Image<float>& depth;
    const Image<glm::vec3>& normal;
    const std::vector<std::uint32_t>& sweep;
    bool nearField;
    bool walls;
    bool smoothstep;
    bool nearest; //!< Gather::Nearest
    float radius;
    float invRadius;
};

//! The receiver of a gather: its view-space point, unit normal and half-slice.
struct Receiver {
    const Slice& slice;
    glm::vec3 x;
    glm::vec3 n;
    float minDistance;
};

//! Gives occluder o (view-space point p) the wall below it where its foot on the receiver's
//! tangent plane is the visible surface (findWallFoot, computeFootSupport): the foot's depth
//! against the tangent plane of the pixel containing its projection; a partly supported wall
//! counts farther away (its distance divided by the support).
void findWall(const GatherContext& g, const Receiver& r, const glm::vec3& p, Occluder& o)
{
    if (!g.walls)
        return;
    const WallFoot f = findWallFoot(r.slice, r.x, r.n, p, o, g.radius);
    if (!f.worth)
        return;
    const glm::vec2 q = g.projection.toPixel(f.foot);
    if (!(q.x >= 0.0f && q.y >= 0.0f && q.x < float(g.layout.width) &&
          q.y < float(g.layout.height)))
        return;
    const glm::ivec2 pixel(int(std::floor(q.x)), int(std::floor(q.y)));
    const float z = loadDepth(g.depth, pixel);
    if (z == 0.0f)
        return;
    const SampleHeight h =
        computeSampleHeight(g.layout, q, pixel, z, g.normal.at(pixel.x, pixel.y));
    const float surface = h.onLine ? h.b / h.a : z;
    const float support = computeFootSupport(-f.foot.z, surface, f.height);
    if (support > 0.0f)
        o.wall = f.wall / support;
}

//! The G-buffer point of `pixel` (its centre at its depth) as an occluder of the slice.
Occluder loadOccluder(const GatherContext& g, glm::ivec2 pixel, const Receiver& r)
{
    const float z = loadDepth(g.depth, pixel);
    if (z == 0.0f)
        return Occluder{};
    const glm::vec3 p = g.projection.toView(glm::vec2(pixel) + 0.5f, z);
    Occluder o = projectOccluder(r.slice, r.x, p, r.minDistance);
    findWall(g, r, p, o);
    return o;
}

//! The view-space point of a line sample: on its line at the depth of its pixel's tangent plane
//! (computeSampleHeight), or where that is rejected the pixel centre's G-buffer point.
Occluder loadLineSample(const GatherContext& g, const Direction& d, float c,
                        const LineSample& sample, const Receiver& r)
{
    const float z = sample.exists ? loadDepth(g.depth, sample.pixel) : 0.0f;
    if (z == 0.0f)
        return Occluder{};
    const glm::vec2 q = computeLinePoint(d, sample.t, c);
    const SampleHeight h = computeSampleHeight(g.layout, q, sample.pixel, z,
                                               g.normal.at(sample.pixel.x, sample.pixel.y));
    const glm::vec3 p = h.onLine ? g.projection.toView(q, h.b / h.a)
                                 : g.projection.toView(glm::vec2(sample.pixel) + 0.5f, z);
    Occluder o = projectOccluder(r.slice, r.x, p, r.minDistance);
    findWall(g, r, p, o);
    return o;
}

void addScaled(Contribution& total, float weight, const Contribution& c)
{
    total.obscurance += weight * c.obscurance;
    total.visibility += weight * c.visibility;
    total.moment += weight * c.moment;
}

//! The dominant occluder stored for `sample` (kNoOccluder: none) as seen from the receiver.
Occluder loadDominant(const GatherContext& g, const Direction& d, std::uint32_t k,
                      std::uint32_t line, float c, std::uint32_t row, const LineSample& sample,
                      const Receiver& r)
{
    const std::uint32_t id = g.sweep[row + std::uint32_t(sample.stratum)];
    if (id == kNoOccluder)
        return Occluder{};
    const LineSample s = locateSample(g.layout, d, k, line, c, int(id));
    return loadLineSample(g, d, c, s, r);
}

//! Where receiver p lies among the lines of direction d: its position along them, the line
//! below it (the pair i0, i0 + 1 brackets it), the weight of line i0 + 1, and its step stratum.
struct ReceiverOnLines {
    float t;
    int lowerLine;
    float lineWeight;
    int stratum;
};

ReceiverOnLines locateReceiver(const Layout& layout, const Direction& d, glm::vec2 p)
{
    const float cX = p.x * d.perp.x + p.y * d.perp.y;
    const float tX = p.x * d.dir.x + p.y * d.dir.y;
    const float fl = (cX - d.cMin) * layout.invSpacing;
    const int i0 = std::clamp(int(std::floor(fl)), 0, int(d.lineCount) - 2);
    return {tX, i0, std::clamp(fl - float(i0), 0.0f, 1.0f),
            int(std::floor((tX - d.tMin) * layout.invStep))};
}

//! Gather::Bilinear: the contribution of direction k at receiver r (pixel centre p).
//! [Timonen 2013: gathering] bilinear over the two lines that bracket p and the two samples that
//! bracket it along each line; each sample's dominant occluder (from the sweep) is seen from the
//! receiver itself, with the receiver's normal [Quantum Break seed: occluders clamped to the
//! visible hemisphere]. The gap between the upstream sample and the receiver gets one near-field
//! sample half-way [Quantum Break seed].
Contribution gatherBilinear(const GatherContext& g, std::uint32_t k, glm::vec2 p, const Receiver& r,
                            const ReceiverOnLines& at)
{
    const Layout& layout = g.layout;
    const Direction& d = layout.directions[k];
    const Slice& slice = r.slice;
    Contribution total;
    const float tX = at.t;
    const int i0 = at.lowerLine;
    const float f = at.lineWeight;
    const int mX = at.stratum;

    LineSample lower[2], upper[2];
    float gap = 0.0f;
    for (int j = 0; j < 2; ++j) {
        const std::uint32_t line = std::uint32_t(i0 + j);
        const float c = computeLineOffset(d, line, layout.spacing);
        // The sample of X's stratum brackets X from below or from above.
        const LineSample atX = locateSample(layout, d, k, line, c, mX);
        if (atX.t <= tX) {
            lower[j] = atX;
            upper[j] = locateSample(layout, d, k, line, c, mX + 1);
        } else {
            lower[j] = locateSample(layout, d, k, line, c, mX - 1);
            upper[j] = atX;
        }
        const float lineGap = lower[j].exists ? tX - lower[j].t : layout.step;
        gap += (j == 0 ? 1.0f - f : f) * lineGap;
    }

    Occluder near;
    if (g.nearField) {
        // [Quantum Break seed] one sample roughly half-way to the nearest upstream sample.
        const float delta = std::max(0.5f * gap, 1.0f);
        const glm::vec2 q(p.x - delta * d.dir.x, p.y - delta * d.dir.y);
        const glm::ivec2 pixel(int(std::floor(q.x)), int(std::floor(q.y)));
        near = loadOccluder(g, pixel, r);
    }

    for (int j = 0; j < 2; ++j) {
        const std::uint32_t line = std::uint32_t(i0 + j);
        const float c = computeLineOffset(d, line, layout.spacing);
        const float lineWeight = j == 0 ? 1.0f - f : f;
        const std::uint32_t row = d.base + line * d.stepCount;
        float wLower = 0.0f, wUpper = 0.0f, wNear = 0.0f;
        if (lower[j].exists && upper[j].exists) {
            wUpper = std::clamp((tX - lower[j].t) / (upper[j].t - lower[j].t), 0.0f, 1.0f);
            wLower = 1.0f - wUpper;
        } else if (lower[j].exists) {
            wLower = 1.0f;
        } else if (upper[j].exists) {
            wUpper = 1.0f;
        } else {
            wNear = 1.0f;
        }
        // Occluders are loaded once per stratum: the downstream sample's dominant occluder is
        // often the upstream sample itself or the upstream sample's dominant occluder (one hull
        // vertex seen from consecutive samples), and loading is a function of the stratum.
        const std::uint32_t lowerId =
            wLower > 0.0f ? g.sweep[row + std::uint32_t(lower[j].stratum)] : kNoOccluder;
        Occluder lowerDominant, self;
        if (wLower > 0.0f) {
            // The upstream sample itself and its dominant occluder.
            lowerDominant = loadDominant(g, d, k, line, c, row, lower[j], r);
            self = loadLineSample(g, d, c, lower[j], r);
            addScaled(total, lineWeight * wLower,
                      evaluateOccluders(slice, lowerDominant, self, near, g.radius, g.invRadius,
                                        g.smoothstep));
        }
        if (wUpper > 0.0f) {
            // The downstream sample's dominant occluder lies at or before the upstream sample.
            const std::uint32_t id = g.sweep[row + std::uint32_t(upper[j].stratum)];
            const Occluder dominant = wLower > 0.0f && id == std::uint32_t(lower[j].stratum) ? self
                                      : wLower > 0.0f && id == lowerId
                                          ? lowerDominant
                                          : loadDominant(g, d, k, line, c, row, upper[j], r);
            addScaled(total, lineWeight * wUpper,
                      evaluateOccluders(slice, dominant, near, Occluder{}, g.radius, g.invRadius,
                                        g.smoothstep));
        }
        if (wNear > 0.0f) {
            addScaled(total, lineWeight * wNear,
                      evaluateOccluders(slice, near, Occluder{}, Occluder{}, g.radius, g.invRadius,
                                        g.smoothstep));
        }
    }
    return total;
}

//! Gather::Nearest: one occluder set per direction, that of the sample
//! nearest to the receiver on the nearest line [Quantum Break seed: "average distance to the
//! nearest step is less than 3 px"], instead of the bilinear blend of four. The sample's
//! dominant occluder, the sample itself when it is upstream, and the near-field sample half-way
//! to the upstream sample of that line.
Contribution gatherNearest(const GatherContext& g, std::uint32_t k, glm::vec2 p, const Receiver& r,
                           const ReceiverOnLines& at)
{
    const Layout& layout = g.layout;
    const Direction& d = layout.directions[k];
    const float tX = at.t;
    const int mX = at.stratum;
    const std::uint32_t line =
        std::uint32_t(at.lineWeight < 0.5f ? at.lowerLine : at.lowerLine + 1);
    const float c = computeLineOffset(d, line, layout.spacing);
    const LineSample atX = locateSample(layout, d, k, line, c, mX);
    const bool atXIsLower = atX.t <= tX;
    const LineSample other = locateSample(layout, d, k, line, c, atXIsLower ? mX + 1 : mX - 1);
    const LineSample& lower = atXIsLower ? atX : other;
    const LineSample& upper = atXIsLower ? other : atX;
    const bool useLower = lower.exists && (!upper.exists || tX - lower.t <= upper.t - tX);
    const LineSample& sample = useLower ? lower : upper;

    Occluder near;
    if (g.nearField) {
        // [Quantum Break seed] one sample roughly half-way to the nearest upstream sample.
        const float gap = lower.exists ? tX - lower.t : layout.step;
        const float delta = std::max(0.5f * gap, 1.0f);
        const glm::vec2 q(p.x - delta * d.dir.x, p.y - delta * d.dir.y);
        near = loadOccluder(g, glm::ivec2(int(std::floor(q.x)), int(std::floor(q.y))), r);
    }
    const std::uint32_t row = d.base + line * d.stepCount;
    const Occluder dominant =
        sample.exists ? loadDominant(g, d, k, line, c, row, sample, r) : Occluder{};
    const Occluder self = useLower ? loadLineSample(g, d, c, lower, r) : Occluder{};
    return evaluateOccluders(r.slice, dominant, self, near, g.radius, g.invRadius, g.smoothstep);
}

//! The contribution of direction k at receiver x (pixel centre p, unit normal n), by the gather
//! of Params::gather.
Contribution gatherDirection(const GatherContext& g, std::uint32_t k, glm::vec2 p,
                             const glm::vec3& x, const glm::vec3& n)
{
    const Direction& d = g.layout.directions[k];
    const Slice slice = makeSlice(x, n, glm::vec3(d.axis));
    if (!slice.hasHemisphere)
        return Contribution{};
    const Receiver r{slice, x, n, 1e-4f * glm::length(x)};
    const ReceiverOnLines at = locateReceiver(g.layout, d, p);
    return g.nearest ? gatherNearest(g, k, p, r, at) : gatherBilinear(g, k, p, r, at);
}

} // namespace

std::vector<std::uint32_t> runSweepCpu(const Layout& layout, std::size_t batchIndex,
                                       const Image<float>& depth, const Image<glm::vec3>& normal)
{
    const Batch& batch = layout.batches[batchIndex];
    std::vector<std::uint32_t> sweep(batch.entryCount, kNoOccluder);
    // One task per (direction, line), as one GPU invocation per line.
    std::vector<std::pair<std::uint32_t, std::uint32_t>> lines;
    for (std::uint32_t k = batch.begin; k < batch.end; ++k)
        for (std::uint32_t i = 0; i < layout.directions[k].lineCount; ++i)
            lines.emplace_back(k, i);
    tbb::parallel_for(
        tbb::blocked_range<std::size_t>(0, lines.size(), 32),
        [&](const tbb::blocked_range<std::size_t>& range) {
            for (std::size_t r = range.begin(); r != range.end(); ++r) {
                const auto [k, line] = lines[r];
                const Direction& d = layout.directions[k];
                const float c = computeLineOffset(d, line, layout.spacing);
                std::uint32_t* out = sweep.data() + d.base + std::size_t(line) * d.stepCount;
                // [Timonen 2013: sweeps] walk the line across the whole depth buffer; the hull
                // holds every earlier sample that can still be a horizon.
                OccluderHull hull;
                for (std::uint32_t m = 0; m < d.stepCount; ++m) {
                    const LineSample s = locateSample(layout, d, k, line, c, int(m));
                    const float z = s.exists ? loadDepth(depth, s.pixel) : 0.0f;
                    if (z == 0.0f)
                        continue; // outside or sky: no point, no occluder (entry stays kNoOccluder)
                    const SampleHeight h =
                        computeSampleHeight(layout, computeLinePoint(d, s.t, c), s.pixel, z,
                                            normal.at(s.pixel.x, s.pixel.y));
                    out[m] = hull.findDominant(s.t, h);
                    hull.push(s.t, h, m);
                }
            }
        });
    return sweep;
}

void runGatherCpu(const Layout& layout, std::size_t batchIndex,
                  const plugin::ScreenProjection& projection, const Params& params,
                  const Image<float>& depth, const Image<glm::vec3>& normal,
                  const std::vector<std::uint32_t>& sweep, Accumulators& sums)
{
    const Batch& batch = layout.batches[batchIndex];
    const GatherContext g{layout,
                          projection,
                          depth,
                          normal,
                          sweep,
                          params.nearField,
                          params.walls,
                          params.falloff == Falloff::Smoothstep,
                          params.gather == Gather::Nearest,
                          float(params.radius),
                          params.radius > 0.0 ? float(1.0 / params.radius)
                                              : std::numeric_limits<float>::infinity()};
    const int w = layout.width;
    const int interleave = layout.interleave;
    tbb::parallel_for(
        tbb::blocked_range<int>(0, layout.height), [&](const tbb::blocked_range<int>& rows) {
            for (int py = rows.begin(); py != rows.end(); ++py) {
                for (int px = 0; px < w; ++px) {
                    const float z = depth.at(px, py);
                    const glm::vec3 nRaw = normal.at(px, py);
                    if (!hasSurface(z, nRaw))
                        continue;
                    const glm::vec3 n = glm::normalize(nRaw);
                    const glm::vec2 p(float(px) + 0.5f, float(py) + 0.5f);
                    const glm::vec3 x = projection.toView(p, z);
                    const std::size_t i = std::size_t(py) * std::size_t(w) + std::size_t(px);
                    // [Quantum Break seed] this pixel's share of the directions: k = class mod n^2.
                    const std::uint32_t classes = std::uint32_t(interleave * interleave);
                    const std::uint32_t pixelClass = computePixelClass(px, py, interleave);
                    const std::uint32_t first =
                        batch.begin + (pixelClass + classes - batch.begin % classes) % classes;
                    for (std::uint32_t k = first; k < batch.end; k += classes) {
                        const Contribution c = gatherDirection(g, k, p, x, n);
                        sums.obscurance[i] += c.obscurance;
                        sums.visibility[i] += c.visibility;
                        sums.moment[i] += c.moment;
                    }
                }
            }
        });
}

void computeOnCpu(const Layout& layout, const plugin::ScreenProjection& projection,
                  const Params& params, const Image<float>& depth, const Image<glm::vec3>& normal,
                  plugin::OcclusionOutput& out)
{
    const int w = layout.width, h = layout.height;
    const std::size_t count = std::size_t(w) * std::size_t(h);
    Accumulators sums{std::vector<float>(count, 0.0f), std::vector<float>(count, 0.0f),
                      std::vector<glm::vec3>(count, glm::vec3(0.0f))};
    for (std::size_t b = 0; b < layout.batches.size(); ++b) {
        const std::vector<std::uint32_t> sweep = runSweepCpu(layout, b, depth, normal);
        runGatherCpu(layout, b, projection, params, depth, normal, sweep, sums);
    }
    out.ambient = Image<float>(w, h, 1.0f);
    out.bentNormal = Image<glm::vec3>(w, h, glm::vec3(0.0f));
    out.coneAperture = Image<float>(w, h, 0.0f);
    out.coneVisibility.clear();
    const std::uint32_t directionCount = std::uint32_t(layout.directions.size());
    const int n = layout.interleave;
    const int begin = computeWindowBegin(n);
    tbb::parallel_for(tbb::blocked_range<int>(0, h), [&](const tbb::blocked_range<int>& rows) {
        for (int py = rows.begin(); py != rows.end(); ++py) {
            for (int px = 0; px < w; ++px) {
                const glm::vec3 nRaw = normal.at(px, py);
                const float z = depth.at(px, py);
                if (!hasSurface(z, nRaw))
                    continue;
                const glm::vec2 pi = glm::vec2(px, py) + 0.5f;
                // [Quantum Break seed] the n x n window holds one pixel of every class: the sums
                // of the neighbours on the receiver's surface (the receiver always), each scaled
                // from its share of the directions to all of them, are averaged.
                float obscurance = 0.0f, visibility = 0.0f, count = 0.0f;
                glm::vec3 moment(0.0f);
                for (int dy = begin; dy < begin + n; ++dy) {
                    for (int dx = begin; dx < begin + n; ++dx) {
                        const int qx = px + dx, qy = py + dy;
                        if (qx < 0 || qy < 0 || qx >= w || qy >= h)
                            continue;
                        const glm::vec3 nq = normal.at(qx, qy);
                        const float zq = depth.at(qx, qy);
                        if (!hasSurface(zq, nq))
                            continue;
                        if ((dx != 0 || dy != 0) &&
                            !isSameSurface(pi, z, nRaw, glm::vec2(qx, qy) + 0.5f, zq, nq,
                                           projection.scale, projection.offset, layout.invSize))
                            continue;
                        const float share = float(directionCount) /
                                            float(countClassDirections(computePixelClass(qx, qy, n),
                                                                       directionCount, n));
                        const std::size_t q = std::size_t(qy) * std::size_t(w) + std::size_t(qx);
                        obscurance += share * sums.obscurance[q];
                        visibility += share * sums.visibility[q];
                        moment += share * sums.moment[q];
                        count += 1.0f;
                    }
                }
                const float inv = 1.0f / count;
                const PixelResult r =
                    resolvePixel(glm::normalize(nRaw), inv * obscurance, inv * visibility,
                                 inv * moment, int(directionCount));
                out.ambient.at(px, py) = r.ambient;
                out.bentNormal.at(px, py) = r.bentNormal;
                out.coneAperture.at(px, py) = r.aperture;
            }
        }
    });
}

} // namespace rtlab::occlusion::lsao
