#include "reference/screen_space_reference.h"

#include "core/error.h"
#include "reference/bent_estimate.h"
#include "reference/exr_io.h"
#include "reference/prepared.h"
#include "reference/progressive.h"
#include "reference/samplers.h"
#include "reference/sequences.h"

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>

#include <tbb/enumerable_thread_specific.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

namespace rtlab::reference {

namespace {

// The Sobol pairs of evaluateOcclusionSample: cosine (or uniform) directions, and the uniform
// directions of the bent cone's solid-angle aperture.
constexpr std::uint32_t kPairMain = 0;
constexpr std::uint32_t kPairUniform = 1;
constexpr double kInf = std::numeric_limits<double>::infinity();

//! c[0] + c[1] s + c[2] s^2 + c[3] s^3.
struct Polynomial {
    std::array<double, 4> c{};
    int degree = 0;

    double operator()(double s) const { return ((c[3] * s + c[2]) * s + c[1]) * s + c[0]; }

    Polynomial getDerivative() const
    {
        Polynomial d;
        d.degree = std::max(0, degree - 1);
        for (int k = 1; k <= degree; ++k)
            d.c[k - 1] = double(k) * c[k];
        return d;
    }
};

//! Appends the roots of p in [a, b] where p changes sign (at most `degree`): p is monotone
//! between consecutive roots of its derivative, and each sign change there is bisected.
int findSignChanges(const Polynomial& p, double a, double b, double* roots)
{
    if (p.degree == 0 || !(b > a))
        return 0;
    std::array<double, 5> breaks{};
    int n = 0;
    breaks[n++] = a;
    if (p.degree >= 2)
        n += findSignChanges(p.getDerivative(), a, b, breaks.data() + n);
    breaks[n++] = b;
    int count = 0;
    for (int i = 0; i + 1 < n; ++i) {
        double lo = breaks[i];
        double hi = breaks[i + 1];
        const double flo = p(lo);
        const double fhi = p(hi);
        if (fhi == 0.0) {
            roots[count++] = hi;
            continue;
        }
        if (flo == 0.0 || (flo < 0.0) == (fhi < 0.0))
            continue;
        const double tolerance = (b - a) * 1e-13;
        for (int it = 0; it < 200 && hi - lo > tolerance; ++it) {
            const double mid = 0.5 * (lo + hi);
            if ((p(mid) < 0.0) == (flo < 0.0))
                lo = mid;
            else
                hi = mid;
        }
        roots[count++] = 0.5 * (lo + hi);
    }
    return std::min(count, p.degree);
}

//! The smallest s in [0, length] from which every polynomial is positive on an interval.
std::optional<double> findFirstPositive(const Polynomial* polys, int count, double length)
{
    std::array<double, 12> breaks{};
    int n = 0;
    breaks[n++] = 0.0;
    breaks[n++] = length;
    for (int i = 0; i < count; ++i)
        n += findSignChanges(polys[i], 0.0, length, breaks.data() + n);
    std::sort(breaks.begin(), breaks.begin() + n);
    for (int i = 0; i + 1 < n; ++i) {
        if (!(breaks[i + 1] > breaks[i]))
            continue;
        const double mid = 0.5 * (breaks[i] + breaks[i + 1]);
        bool positive = true;
        for (int k = 0; k < count && positive; ++k)
            positive = polys[k](mid) > 0.0;
        if (positive)
            return breaks[i];
    }
    return std::nullopt;
}

struct TraceOutcome {
    bool occluded = false;
    double distance = kInf; //!< from the origin, when occluded
    bool leftImage = false; //!< unoccluded because the ray left the image first
};

//! One pixel's piece of the height field: over its footprint [x, x+1) x [y, y+1) the inverse
//! depth is the affine w + slope . (pixel position - centre).
struct Facet {
    double w = 0.0;
    glm::dvec2 slope{0.0};
};

//! The depth buffer as a height field in (pixel x, pixel y, w = 1/depth) space.
class HeightField {
public:
    HeightField(const ScreenSpaceView& view, const ScreenSpaceOptions& options);

    //! View-space point of pixel (x, y) at linear depth `depth` (ScreenProjection::toView).
    glm::dvec3 getPoint(int x, int y, double depth) const
    {
        const double ndcX = 2.0 * (x + 0.5) / mWidth - 1.0;
        const double ndcY = 2.0 * (y + 0.5) / mHeight - 1.0;
        return {depth * (ndcX + mOffset.x) / mScale.x, depth * (ndcY + mOffset.y) / mScale.y,
                -depth};
    }

    //! First occlusion along origin + t direction, t in [0, radius]; origin.z < 0.
    TraceOutcome trace(const glm::dvec3& origin, const glm::dvec3& direction, double radius,
                       std::uint64_t& cells) const;

private:
    const Facet& getFacet(int x, int y) const
    {
        return mFacets[std::size_t(y) * std::size_t(mWidth) + std::size_t(x)];
    }

    //! The first occluded point over pixel (ix, iy) between sigma = a and b, as sigma.
    std::optional<double> intersectPixel(int ix, int iy, double a, double b, const glm::dvec2& p0,
                                         const glm::dvec2& pd, double w0, double wd) const;

    int mWidth;
    int mHeight;
    glm::dvec2 mScale;
    glm::dvec2 mOffset;
    double mBiasFactor;
    double mThickness;
    std::vector<Facet> mFacets;
    double mMaxInverseDepth = 0.0;
};

HeightField::HeightField(const ScreenSpaceView& view, const ScreenSpaceOptions& options)
    : mWidth(view.linearDepth->width), mHeight(view.linearDepth->height),
      mScale(view.projection[0][0], view.projection[1][1]),
      mOffset(view.projection[2][0], view.projection[2][1]),
      mBiasFactor(1.0 / (1.0 + options.depthBias)), mThickness(options.thickness)
{
    const std::size_t count = view.linearDepth->pixels.size();
    std::vector<double> w(count, 0.0);
    for (std::size_t i = 0; i < count; ++i) {
        const double d = view.linearDepth->pixels[i];
        w[i] = std::isfinite(d) && d > 0.0 ? 1.0 / d : 0.0;
        mMaxInverseDepth = std::max(mMaxInverseDepth, w[i]);
    }
    auto at = [&](int x, int y) {
        return w[std::size_t(y) * std::size_t(mWidth) + std::size_t(x)];
    };
    const glm::ivec2 size(mWidth, mHeight);
    mFacets.resize(count);
    for (int y = 0; y < mHeight; ++y) {
        for (int x = 0; x < mWidth; ++x) {
            const std::size_t i = std::size_t(y) * std::size_t(mWidth) + std::size_t(x);
            Facet& f = mFacets[i];
            f.w = w[i];
            if (!(f.w > 0.0))
                continue;
            // The plane of the normal: depth = k / (n . r) with r = ((ndc + offset) / scale, -1)
            // and k = n . P, so w = n . r / k is affine in the pixel position, with slope
            // 2 n_xy / (size scale k) per pixel.
            const glm::dvec3 n(view.normal->pixels[i]);
            const glm::dvec3 p = getPoint(x, y, 1.0 / f.w);
            const double k = glm::dot(n, p);
            const bool hasNormal =
                std::isfinite(k) && std::abs(k) > 1e-9 * glm::length(p) && glm::dot(n, n) > 0.0;
            for (int axis = 0; axis < 2; ++axis) {
                // One-sided differences of w toward the neighbours with a surface. On a plane
                // both equal the plane's slope exactly (w is affine in screen space); across a
                // crease or silhouette only the side on the pixel's own surface does.
                const glm::ivec2 c(x, y);
                std::array<double, 2> candidates{};
                int n0 = 0;
                for (int side : {-1, 1}) {
                    glm::ivec2 q = c;
                    q[axis] += side;
                    if (q[axis] < 0 || q[axis] >= size[axis])
                        continue;
                    const double wq = at(q.x, q.y);
                    if (wq > 0.0)
                        candidates[n0++] = double(side) * (wq - f.w);
                }
                double slope = 0.0;
                if (hasNormal) {
                    const double normalSlope =
                        2.0 * n[axis] / (double(size[axis]) * mScale[axis] * k);
                    // The difference closest to the normal's plane, unless even that one jumps
                    // by more than a tenth of the pixel's own w (a silhouette): then the plane.
                    slope = normalSlope;
                    double best = kInf;
                    for (int j = 0; j < n0; ++j)
                        if (std::abs(candidates[j] - normalSlope) < best) {
                            best = std::abs(candidates[j] - normalSlope);
                            slope = candidates[j];
                        }
                    if (!(best <= 0.1 * f.w) || !std::isfinite(slope))
                        slope = std::isfinite(normalSlope) ? normalSlope : 0.0;
                } else {
                    // No normal: the smaller difference (the continuous side).
                    for (int j = 0; j < n0; ++j)
                        if (j == 0 || std::abs(candidates[j]) < std::abs(slope))
                            slope = candidates[j];
                }
                f.slope[axis] = slope;
            }
        }
    }
}

std::optional<double> HeightField::intersectPixel(int ix, int iy, double a, double b,
                                                  const glm::dvec2& p0, const glm::dvec2& pd,
                                                  double w0, double wd) const
{
    const Facet& f = getFacet(ix, iy);
    if (!(f.w > 0.0))
        return std::nullopt; // sky never occludes
    // Along the segment, s = sigma - a, the facet's w and the ray's w are affine in s.
    const glm::dvec2 e = p0 + pd * a - glm::dvec2(ix + 0.5, iy + 0.5);
    const double s0 = f.w + glm::dot(f.slope, e);
    const double s1 = glm::dot(f.slope, pd);
    const double rayA = w0 + wd * a;
    const double length = b - a;
    // Behind the surface: z > z_s (1 + bias)  <=>  w_s / (1 + bias) - w > 0.
    std::array<Polynomial, 2> conditions;
    conditions[0].degree = 1;
    conditions[0].c = {mBiasFactor * s0 - rayA, mBiasFactor * s1 - wd, 0.0, 0.0};
    if (conditions[0](0.0) <= 0.0 && conditions[0](length) <= 0.0)
        return std::nullopt; // in front of the facet over the whole segment
    int count = 1;
    if (std::isfinite(mThickness)) {
        // Inside the slab: z < z_s + T  <=>  w - w_s + T w w_s > 0 (w, w_s > 0).
        const double t = mThickness;
        conditions[1].degree = 2;
        conditions[1].c = {rayA - s0 + t * rayA * s0, wd - s1 + t * (rayA * s1 + wd * s0),
                           t * wd * s1, 0.0};
        count = 2;
    }
    if (const auto s = findFirstPositive(conditions.data(), count, length))
        return a + *s;
    return std::nullopt;
}

TraceOutcome HeightField::trace(const glm::dvec3& origin, const glm::dvec3& direction,
                                double radius, std::uint64_t& cells) const
{
    TraceOutcome outcome;
    const double depth0 = -origin.z;
    if (!(depth0 > 0.0))
        return outcome;
    // depth(t) = C + D t; sigma = t / depth(t); 1 / depth(t) = (1 - D sigma) / C; the ratios
    // x / depth and y / depth are affine in sigma, hence so is the pixel position p.
    const double c = depth0;
    const double d = -direction.z;
    const glm::dvec2 ratio0(origin.x / c, origin.y / c);
    const glm::dvec2 ratioD(direction.x - d * ratio0.x, direction.y - d * ratio0.y);
    const glm::dvec2 half(0.5 * mWidth, 0.5 * mHeight);
    const glm::dvec2 p0 = (ratio0 * mScale - mOffset + 1.0) * half;
    const glm::dvec2 pd = ratioD * mScale * half;
    const double w0 = 1.0 / c;
    const double wd = -d / c;

    double sigmaEnd = kInf;
    if (std::isfinite(radius)) {
        const double depthAtRadius = c + d * radius;
        if (depthAtRadius > 0.0)
            sigmaEnd = radius / depthAtRadius;
    }
    if (d > 0.0)
        sigmaEnd = std::min(sigmaEnd, 1.0 / d); // the vanishing point: depth -> infinity
    else if (d < 0.0)
        // Approaching the camera: once nearer than every visible surface it stays in front.
        sigmaEnd = std::min(sigmaEnd, std::max(0.0, (c * mMaxInverseDepth - 1.0) / -d));
    const glm::dvec2 hi(mWidth, mHeight);
    double sigmaImage = kInf;
    for (int k = 0; k < 2; ++k) {
        if (pd[k] > 0.0)
            sigmaImage = std::min(sigmaImage, (hi[k] - p0[k]) / pd[k]);
        else if (pd[k] < 0.0)
            sigmaImage = std::min(sigmaImage, -p0[k] / pd[k]);
    }
    const bool endsAtImage = sigmaImage < sigmaEnd;
    sigmaEnd = std::min(sigmaEnd, sigmaImage);
    if (!(sigmaEnd > 0.0) || !std::isfinite(sigmaEnd))
        return outcome;

    // Pixel walk [Amanatides & Woo 1987] in sigma.
    int ix = std::clamp(int(std::floor(p0.x)), 0, mWidth - 1);
    int iy = std::clamp(int(std::floor(p0.y)), 0, mHeight - 1);
    const int stepX = pd.x > 0.0 ? 1 : -1;
    const int stepY = pd.y > 0.0 ? 1 : -1;
    const double deltaX = pd.x != 0.0 ? std::abs(1.0 / pd.x) : kInf;
    const double deltaY = pd.y != 0.0 ? std::abs(1.0 / pd.y) : kInf;
    double nextX = pd.x > 0.0 ? (ix + 1 - p0.x) / pd.x : pd.x < 0.0 ? (ix - p0.x) / pd.x : kInf;
    double nextY = pd.y > 0.0 ? (iy + 1 - p0.y) / pd.y : pd.y < 0.0 ? (iy - p0.y) / pd.y : kInf;
    double sigma = 0.0;
    while (ix >= 0 && iy >= 0 && ix < mWidth && iy < mHeight) {
        const double sigmaNext = std::min(std::min(nextX, nextY), sigmaEnd);
        ++cells;
        if (sigmaNext > sigma) {
            if (const auto hit = intersectPixel(ix, iy, sigma, sigmaNext, p0, pd, w0, wd)) {
                outcome.occluded = true;
                outcome.distance = *hit * c / (1.0 - d * *hit);
                return outcome;
            }
        }
        if (sigmaNext >= sigmaEnd)
            break;
        if (nextX < nextY) {
            ix += stepX;
            nextX += deltaX;
        } else {
            iy += stepY;
            nextY += deltaY;
        }
        sigma = sigmaNext;
    }
    outcome.leftImage = endsAtImage;
    return outcome;
}

int getScreenSpaceChannelCount(Quantity quantity)
{
    return quantity == Quantity::Bent ? 5 : 1;
}

void validate(const ScreenSpaceView& view, const ReferenceSettings& settings,
              const ScreenSpaceOptions& options)
{
    auto fail = [](const std::string& what) { throw Error("screen-space reference: " + what); };
    if (!view.linearDepth || !view.normal)
        fail("the view needs a linear depth and a normal image");
    const auto& depth = *view.linearDepth;
    const auto& normal = *view.normal;
    if (depth.width <= 0 || depth.height <= 0 ||
        depth.pixels.size() != std::size_t(depth.width) * std::size_t(depth.height))
        fail("the depth image is empty or malformed (" + std::to_string(depth.width) + "x" +
             std::to_string(depth.height) + ")");
    if (normal.width != depth.width || normal.height != depth.height ||
        normal.pixels.size() != depth.pixels.size())
        fail("the normal image is " + std::to_string(normal.width) + "x" +
             std::to_string(normal.height) + " but the depth image is " +
             std::to_string(depth.width) + "x" + std::to_string(depth.height));
    const float sx = view.projection[0][0];
    const float sy = view.projection[1][1];
    if (!std::isfinite(sx) || !std::isfinite(sy) || sx == 0.0f || sy == 0.0f ||
        !std::isfinite(view.projection[2][0]) || !std::isfinite(view.projection[2][1]))
        fail("the projection is not a perspective projection (zero or non-finite scale)");
    switch (settings.quantity) {
    case Quantity::Ao:
    case Quantity::AoUniform:
    case Quantity::Obscurance:
    case Quantity::Bent:
        break;
    default:
        fail(std::string("quantity '") + getQuantityName(settings.quantity) +
             "' is not an occlusion quantity (ao, ao_uniform, obscurance, bent)");
    }
    if (!(settings.radius >= 0.0))
        fail("radius must be >= 0, got " + std::to_string(settings.radius));
    ReferenceSettings checked = settings;
    if (checked.radius == 0.0)
        checked.radius = 1.0; // radius 0 is valid here: nothing to occlude
    validateSettings(checked);
    if (!(options.thickness > 0.0))
        fail("thickness must be > 0 (infinity = solid behind the surface), got " +
             std::to_string(options.thickness));
    if (!(options.depthBias >= 0.0 && options.depthBias <= 0.1))
        fail("depthBias must be in [0, 0.1], got " + std::to_string(options.depthBias));
}

} // namespace

ScreenSpaceResult computeScreenSpaceReference(const ScreenSpaceView& view,
                                              const ReferenceSettings& settings,
                                              const ScreenSpaceOptions& options)
{
    validate(view, settings, options);
    const auto start = std::chrono::steady_clock::now();
    const int width = view.linearDepth->width;
    const int height = view.linearDepth->height;
    const std::size_t pixelCount = std::size_t(width) * std::size_t(height);
    const Quantity quantity = settings.quantity;

    ScreenSpaceResult out;
    ReferenceResult& result = out.reference;
    allocateResultImages(result, quantity, width, height);
    result.settings = settings;
    out.offScreenShare = Image<float>(width, height, 0.0f);

    const HeightField field(view, options);
    // World <-> view rotation of the (rigid) view matrix.
    const glm::dmat3 toView(glm::mat3(view.view));
    const glm::dmat3 toWorld = glm::inverse(toView);

    std::vector<std::uint8_t> active(pixelCount, 0);
    std::vector<glm::dvec3> origins(pixelCount);
    std::vector<Frame> frames(pixelCount);
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            const std::size_t i = std::size_t(y) * std::size_t(width) + std::size_t(x);
            const double depth = view.linearDepth->pixels[i];
            const glm::dvec3 n(view.normal->pixels[i]);
            const double length = glm::length(n);
            if (!std::isfinite(depth) || !(depth > 0.0) || !std::isfinite(length) ||
                !(length > 0.0))
                continue;
            active[i] = 1;
            origins[i] = field.getPoint(x, y, depth);
            frames[i] = Frame::fromNormal(glm::normalize(toWorld * (n / length)));
        }

    ProgressiveRule rule;
    rule.channels = getScreenSpaceChannelCount(quantity);
    rule.targetStdErr = settings.targetStdErr;
    rule.targetRelStdErr = settings.targetRelStdErr;
    rule.batchSize = settings.batchSize;
    rule.maxSamples = settings.maxSamples;

    std::vector<std::uint32_t> raysTraced(pixelCount, 0);
    std::vector<std::uint32_t> raysOffScreen(pixelCount, 0);
    tbb::enumerable_thread_specific<std::uint64_t> cells(0);
    const double radius = settings.radius;

    tbb::task_arena arena(settings.threadCount > 0 ? settings.threadCount
                                                   : int(tbb::task_arena::automatic));
    ProgressiveOutput progressive;
    arena.execute([&] {
        progressive = runProgressive(
            width, height, active, rule,
            [&](std::size_t pixel, std::uint32_t index, SampleValue& value) -> std::uint32_t {
                // Each pixel is sampled by one thread only: its counters need no atomics.
                const PixelSequence sequence(settings.seed, pixel);
                const Frame& frame = frames[pixel];
                std::uint64_t& localCells = cells.local();
                auto trace = [&](const glm::dvec3& worldDirection) {
                    const glm::dvec3 w = glm::normalize(toView * worldDirection);
                    const TraceOutcome o = field.trace(origins[pixel], w, radius, localCells);
                    ++raysTraced[pixel];
                    raysOffScreen[pixel] += o.leftImage ? 1u : 0u;
                    return o;
                };
                switch (quantity) {
                case Quantity::Ao: {
                    const glm::dvec3 w =
                        frame.toWorld(sampleCosineHemisphere(sequence.get2D(index, kPairMain)));
                    value[0] = trace(w).occluded ? 0.0 : 1.0;
                    return 1;
                }
                case Quantity::AoUniform: {
                    const glm::dvec3 w =
                        frame.toWorld(sampleUniformHemisphere(sequence.get2D(index, kPairMain)));
                    value[0] = trace(w).occluded ? 0.0 : 1.0;
                    return 1;
                }
                case Quantity::Obscurance: {
                    // [Zhukov et al. 1998]: rho(d / r) of the first hit, 1 beyond r.
                    const glm::dvec3 w =
                        frame.toWorld(sampleCosineHemisphere(sequence.get2D(index, kPairMain)));
                    const TraceOutcome o = trace(w);
                    value[0] =
                        o.occluded ? evaluateFalloff(settings.falloff, o.distance / radius) : 1.0;
                    return 1;
                }
                case Quantity::Bent: {
                    // Bent normal [Landis 2002] as the mean of V w under cosine-weighted sampling.
                    const glm::dvec3 w =
                        frame.toWorld(sampleCosineHemisphere(sequence.get2D(index, kPairMain)));
                    const double visible = trace(w).occluded ? 0.0 : 1.0;
                    value[0] = visible * w.x;
                    value[1] = visible * w.y;
                    value[2] = visible * w.z;
                    value[3] = visible;
                    const glm::dvec3 wu =
                        frame.toWorld(sampleUniformHemisphere(sequence.get2D(index, kPairUniform)));
                    value[4] = trace(wu).occluded ? 0.0 : 1.0;
                    return 2;
                }
                default:
                    return 0;
                }
            });
    });

    double sampleSum = 0.0;
    double offScreenSum = 0.0;
    for (std::size_t i = 0; i < pixelCount; ++i) {
        if (!active[i])
            continue;
        const PixelEstimate& e = progressive.pixels[i];
        ++result.stats.surfacePixels;
        sampleSum += e.samples;
        result.sampleCount.pixels[i] = e.samples;
        if (!e.converged)
            ++result.stats.pixelsAtCap;
        for (int c = 0; c < rule.channels; ++c)
            result.stats.maxStdErr = std::max(result.stats.maxStdErr, e.getStdErr(c));
        if (quantity == Quantity::Bent) {
            storeBentEstimate(result, i, e, frames[i].normal);
        } else {
            result.occlusion.pixels[i] = float(e.mean[0]);
            result.occlusionStdErr.pixels[i] = float(e.getStdErr(0));
        }
        const float share =
            raysTraced[i] > 0 ? float(double(raysOffScreen[i]) / double(raysTraced[i])) : 0.0f;
        out.offScreenShare.pixels[i] = share;
        offScreenSum += share;
    }
    const int surface = result.stats.surfacePixels;
    result.stats.meanSamples = surface > 0 ? sampleSum / surface : 0.0;
    result.stats.rayCount = progressive.rayCount;
    out.meanOffScreenShare = surface > 0 ? offScreenSum / surface : 0.0;
    for (std::uint64_t c : cells)
        out.cellsVisited += c;
    result.stats.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return out;
}

} // namespace rtlab::reference
