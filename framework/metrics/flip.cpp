// FLIP, implemented from the descriptions in
//   [FLIP]    P. Andersson, J. Nilsson, T. Akenine-Moeller, M. Oskarsson, K. Astroem,
//             M. D. Fairchild, "FLIP: A Difference Evaluator for Alternating Images", Proc. ACM
//             Comput. Graph. Interact. Tech. 3(2) (HPG 2020), Article 15.
//   [HDR-FLIP] P. Andersson, J. Nilsson, P. Shirley, T. Akenine-Moeller, "Visualizing Errors in
//             Rendered High Dynamic Range Images", Eurographics 2021 short papers.
// Citations name the part of the paper a step comes from: for FLIP its "color pipeline" (spatial
// filtering, perceptually uniform color space, color metric), "feature pipeline", "final error"
// and "viewing conditions"; for HDR-FLIP the "tone mapping", "exposure range" and "combination"
// of LDR-FLIP evaluations.
#include "metrics/image_metrics.h"

#include "metrics/image_metrics_detail.h"

#include <glm/mat3x3.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace rtlab::metrics {

namespace {

using detail::Plane;

constexpr double kPi = 3.14159265358979323846;

// ------------------------------------------------------------------------------------------------
// Colour spaces (sRGB primaries, D65 white)

struct ColorSpace {
    glm::dmat3 rgbToXyz; // linear sRGB -> CIE XYZ (Y of white = 1)
    glm::dmat3 xyzToRgb;
    glm::dvec3 white; // XYZ of the D65 white, rgbToXyz * (1, 1, 1)
};

// The sRGB (IEC 61966-2-1) matrix derived from its primaries' chromaticities and D65, so that
// RGB (1, 1, 1) maps exactly to the white point and the inverse is consistent.
const ColorSpace& getSrgbColorSpace()
{
    static const ColorSpace space = [] {
        const auto xyzOf = [](double x, double y) {
            return glm::dvec3(x / y, 1.0, (1 - x - y) / y);
        };
        // glm matrices are column-major: column i holds primary i.
        const glm::dmat3 primaries(xyzOf(0.64, 0.33), xyzOf(0.30, 0.60), xyzOf(0.15, 0.06));
        const glm::dvec3 white = xyzOf(0.3127, 0.3290);
        const glm::dvec3 scale = glm::inverse(primaries) * white;
        ColorSpace s;
        s.rgbToXyz =
            glm::dmat3(primaries[0] * scale.x, primaries[1] * scale.y, primaries[2] * scale.z);
        s.xyzToRgb = glm::inverse(s.rgbToXyz);
        s.white = s.rgbToXyz * glm::dvec3(1.0);
        return s;
    }();
    return space;
}

double decodeSrgb(double v)
{
    return v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4);
}

// [FLIP, color pipeline, spatial filtering] the linearised CIELAB opponent space YyCxCz:
// Yy = 116 Y/Yn - 16, Cx = 500 (X/Xn - Y/Yn), Cz = 200 (Y/Yn - Z/Zn).
glm::dvec3 convertLinearRgbToYcxcz(const glm::dvec3& rgb)
{
    const ColorSpace& cs = getSrgbColorSpace();
    const glm::dvec3 n = (cs.rgbToXyz * rgb) / cs.white;
    return {116.0 * n.y - 16.0, 500.0 * (n.x - n.y), 200.0 * (n.y - n.z)};
}

glm::dvec3 convertYcxczToLinearRgb(const glm::dvec3& ycxcz)
{
    const ColorSpace& cs = getSrgbColorSpace();
    const double y = (ycxcz.x + 16.0) / 116.0;
    const glm::dvec3 n(y + ycxcz.y / 500.0, y, y - ycxcz.z / 200.0);
    return cs.xyzToRgb * (n * cs.white);
}

// CIE 1976 L*a*b* of a linear sRGB colour (D65 white).
glm::dvec3 convertLinearRgbToLab(const glm::dvec3& rgb)
{
    const ColorSpace& cs = getSrgbColorSpace();
    const glm::dvec3 n = (cs.rgbToXyz * rgb) / cs.white;
    constexpr double delta = 6.0 / 29.0;
    const auto f = [&](double t) {
        return t > delta * delta * delta ? std::cbrt(t) : t / (3 * delta * delta) + 4.0 / 29.0;
    };
    const double fx = f(n.x), fy = f(n.y), fz = f(n.z);
    return {116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz)};
}

// [FLIP, color pipeline, perceptually uniform color space] Hunt adjustment: chroma grows with
// lightness, a* and b* are scaled by 0.01 L*.
glm::dvec3 applyHuntAdjustment(const glm::dvec3& lab)
{
    return {lab.x, 0.01 * lab.x * lab.y, 0.01 * lab.x * lab.z};
}

// [FLIP, color pipeline, color metric] HyAB distance: |dL| + ||(da, db)||.
double computeHyab(const glm::dvec3& a, const glm::dvec3& b)
{
    const glm::dvec3 d = a - b;
    return std::abs(d.x) + std::sqrt(d.y * d.y + d.z * d.z);
}

// ------------------------------------------------------------------------------------------------
// Constants

// [FLIP, color pipeline, color metric] exponent of the colour difference.
constexpr double kQc = 0.7;
// [FLIP, feature pipeline] exponent of the feature difference.
constexpr double kQf = 0.5;
// [FLIP, color pipeline, color metric] error redistribution: differences below pc * cmax map
// linearly to [0, pt], the rest to (pt, 1].
constexpr double kPc = 0.4;
constexpr double kPt = 0.95;
// [FLIP, feature pipeline] peak-to-trough width of the edge detector, degrees of visual angle;
// the Gaussian's standard deviation is half of it.
constexpr double kFeatureWidthDegrees = 0.082;

// [FLIP, color pipeline, spatial filtering] contrast sensitivity functions as sums of two
// Gaussians in the spatial domain, a1 sqrt(pi/b1) exp(-pi^2 r^2 / b1) + a2 sqrt(pi/b2)
// exp(-pi^2 r^2 / b2), r in degrees. a2 = 0 for the achromatic and red-green channels.
struct CsfParameters {
    double a1, b1, a2, b2;
};
constexpr CsfParameters kCsfAchromatic{1.0, 0.0047, 0.0, 1e-5};
constexpr CsfParameters kCsfRedGreen{1.0, 0.0053, 0.0, 1e-5};
constexpr CsfParameters kCsfBlueYellow{34.1, 0.04, 13.5, 0.025};

// ------------------------------------------------------------------------------------------------
// Filters

std::vector<float> normalizeKernel(std::vector<double> k)
{
    double sum = 0;
    for (double v : k)
        sum += v;
    std::vector<float> out(k.size());
    for (std::size_t i = 0; i < k.size(); ++i)
        out[i] = float(k[i] / sum);
    return out;
}

// One channel's CSF filter as (at most) two separable Gaussians and their weights, normalised so
// that the whole 2D filter sums to 1.
struct CsfFilter {
    std::vector<float> g1, g2; // 1D factors, each summing to 1
    float w1 = 1, w2 = 0;      // weights of the two separable terms, w1 + w2 = 1
};

CsfFilter makeCsfFilter(const CsfParameters& p, double pixelsPerDegree)
{
    // [FLIP, color pipeline, spatial filtering] the filters are evaluated over a square of radius
    // 3 standard deviations of the widest Gaussian (b = 0.04); exp(-pi^2 r^2 / b) has standard
    // deviation sqrt(b / (2 pi^2)) degrees.
    const double maxB = std::max({kCsfAchromatic.b1, kCsfAchromatic.b2, kCsfRedGreen.b1,
                                  kCsfRedGreen.b2, kCsfBlueYellow.b1, kCsfBlueYellow.b2});
    const int radius = int(std::ceil(3.0 * std::sqrt(maxB / (2 * kPi * kPi)) * pixelsPerDegree));
    const auto gaussian = [&](double b, double& sum) {
        std::vector<double> g(std::size_t(2 * radius + 1));
        sum = 0;
        for (int i = -radius; i <= radius; ++i) {
            const double r = i / pixelsPerDegree; // degrees
            g[std::size_t(i + radius)] = std::exp(-kPi * kPi * r * r / b);
            sum += g[std::size_t(i + radius)];
        }
        return g;
    };
    // The 2D filter a1 sqrt(pi/b1) e1(x) e1(y) + a2 sqrt(pi/b2) e2(x) e2(y) sums to
    // a1 sqrt(pi/b1) E1^2 + a2 sqrt(pi/b2) E2^2 (Ei the 1D sums); dividing by that normalises it.
    double sum1 = 0, sum2 = 0;
    CsfFilter f;
    const std::vector<double> e1 = gaussian(p.b1, sum1);
    const double mass1 = p.a1 * std::sqrt(kPi / p.b1) * sum1 * sum1;
    double mass2 = 0;
    f.g1 = normalizeKernel(e1);
    if (p.a2 != 0) {
        const std::vector<double> e2 = gaussian(p.b2, sum2);
        mass2 = p.a2 * std::sqrt(kPi / p.b2) * sum2 * sum2;
        f.g2 = normalizeKernel(e2);
    }
    f.w1 = float(mass1 / (mass1 + mass2));
    f.w2 = float(mass2 / (mass1 + mass2));
    return f;
}

Plane applyCsf(const Plane& in, const CsfFilter& f)
{
    Plane out = detail::filterSeparable(in, f.g1, f.g1);
    if (f.g2.empty())
        return out;
    const Plane second = detail::filterSeparable(in, f.g2, f.g2);
    for (std::size_t i = 0; i < out.values.size(); ++i)
        out.values[i] = f.w1 * out.values[i] + f.w2 * second.values[i];
    return out;
}

// [FLIP, feature pipeline] edge and point detectors: first and second partial derivatives of a
// 2D Gaussian with standard deviation 0.5 * 0.082 degrees, over a radius of 3 standard deviations;
// the positive weights are normalised to sum to 1 and the negative ones to -1. Both are
// separable: derivative along one axis times a Gaussian (summing to 1) along the other.
struct FeatureFilters {
    std::vector<float> smooth; // Gaussian, sums to 1
    std::vector<float> edge;   // -x g(x), positive part sums to 1, negative part to -1
    std::vector<float> point;  // (x^2 / s^2 - 1) g(x), likewise
};

FeatureFilters makeFeatureFilters(double pixelsPerDegree)
{
    const double sd = 0.5 * kFeatureWidthDegrees * pixelsPerDegree; // pixels
    const int radius = int(std::ceil(3.0 * sd));
    const std::size_t n = std::size_t(2 * radius + 1);
    std::vector<double> g(n), edge(n), point(n);
    for (int i = -radius; i <= radius; ++i) {
        const double gi = std::exp(-double(i * i) / (2 * sd * sd));
        g[std::size_t(i + radius)] = gi;
        edge[std::size_t(i + radius)] = -i * gi;
        point[std::size_t(i + radius)] = (double(i * i) / (sd * sd) - 1.0) * gi;
    }
    const auto normalizeSignedKernel = [](const std::vector<double>& k) {
        double positive = 0, negative = 0;
        for (double v : k)
            (v > 0 ? positive : negative) += std::abs(v);
        std::vector<float> out(k.size());
        for (std::size_t i = 0; i < k.size(); ++i)
            out[i] = float(k[i] > 0 ? k[i] / positive : k[i] / negative);
        return out;
    };
    return {normalizeKernel(g), normalizeSignedKernel(edge), normalizeSignedKernel(point)};
}

// ------------------------------------------------------------------------------------------------
// LDR-FLIP on linear RGB in [0, 1]

struct LinearRgbPlanes {
    Plane r, g, b;
};

LinearRgbPlanes convertToLinearPlanes(const Image<glm::vec3>& image, ColorEncoding encoding)
{
    LinearRgbPlanes p{Plane(image.width, image.height), Plane(image.width, image.height),
                      Plane(image.width, image.height)};
    for (std::size_t i = 0; i < image.pixels.size(); ++i) {
        // LDR-FLIP is defined on [0, 1]: clamp first (NaN passes through std::clamp unchanged).
        glm::dvec3 c = glm::dvec3(std::clamp(image.pixels[i].x, 0.0f, 1.0f),
                                  std::clamp(image.pixels[i].y, 0.0f, 1.0f),
                                  std::clamp(image.pixels[i].z, 0.0f, 1.0f));
        if (encoding == ColorEncoding::Srgb)
            c = glm::dvec3(decodeSrgb(c.x), decodeSrgb(c.y), decodeSrgb(c.z));
        p.r.values[i] = float(c.x);
        p.g.values[i] = float(c.y);
        p.b.values[i] = float(c.z);
    }
    return p;
}

struct FlipKernels {
    CsfFilter achromatic, redGreen, blueYellow;
    FeatureFilters features;
    double cmax = 0; // (HyAB between Hunt-adjusted green and blue)^qc
};

FlipKernels makeFlipKernels(double pixelsPerDegree)
{
    if (!(pixelsPerDegree > 0) || !std::isfinite(pixelsPerDegree))
        throw std::invalid_argument("computeFlip: pixelsPerDegree must be finite and > 0, got " +
                                    std::to_string(pixelsPerDegree));
    FlipKernels k;
    k.achromatic = makeCsfFilter(kCsfAchromatic, pixelsPerDegree);
    k.redGreen = makeCsfFilter(kCsfRedGreen, pixelsPerDegree);
    k.blueYellow = makeCsfFilter(kCsfBlueYellow, pixelsPerDegree);
    k.features = makeFeatureFilters(pixelsPerDegree);
    // [FLIP, color pipeline, color metric] the largest difference between two colours of the RGB
    // cube in Hunt-adjusted L*a*b* is between pure green and pure blue.
    const glm::dvec3 green = applyHuntAdjustment(convertLinearRgbToLab({0, 1, 0}));
    const glm::dvec3 blue = applyHuntAdjustment(convertLinearRgbToLab({0, 0, 1}));
    k.cmax = std::pow(computeHyab(green, blue), kQc);
    return k;
}

// Colour-pipeline input of one image: CSF-filtered, back in linear RGB clamped to the unit cube,
// as Hunt-adjusted L*a*b*. Also returns the normalised luminance Y/Yn for the feature pipeline.
struct PreparedImage {
    std::vector<glm::vec3> huntLab;
    Plane luminance;
};

PreparedImage prepareImage(const LinearRgbPlanes& rgb, const FlipKernels& k)
{
    const int w = rgb.r.width, h = rgb.r.height;
    const std::size_t n = rgb.r.values.size();
    Plane yy(w, h), cx(w, h), cz(w, h);
    PreparedImage out;
    out.luminance = Plane(w, h);
    for (std::size_t i = 0; i < n; ++i) {
        const glm::dvec3 o =
            convertLinearRgbToYcxcz({rgb.r.values[i], rgb.g.values[i], rgb.b.values[i]});
        yy.values[i] = float(o.x);
        cx.values[i] = float(o.y);
        cz.values[i] = float(o.z);
        // [FLIP, feature pipeline] features are detected on the achromatic channel normalised to
        // [0, 1]: (Yy + 16) / 116 = Y / Yn.
        out.luminance.values[i] = float((o.x + 16.0) / 116.0);
    }
    // [FLIP, color pipeline, spatial filtering] each opponent channel is convolved with its CSF.
    const Plane fy = applyCsf(yy, k.achromatic);
    const Plane fcx = applyCsf(cx, k.redGreen);
    const Plane fcz = applyCsf(cz, k.blueYellow);
    out.huntLab.resize(n);
    detail::forEachRowBlock(h, [&](int y0, int y1) {
        for (std::size_t i = std::size_t(y0) * w; i < std::size_t(y1) * w; ++i) {
            // [FLIP, color pipeline, spatial filtering] back to linear RGB, clamped to [0, 1]^3
            // (filtering can leave the gamut), then [perceptually uniform color space] to
            // L*a*b* with the Hunt adjustment.
            glm::dvec3 c = convertYcxczToLinearRgb({fy.values[i], fcx.values[i], fcz.values[i]});
            c = glm::clamp(c, glm::dvec3(0.0), glm::dvec3(1.0));
            out.huntLab[i] = glm::vec3(applyHuntAdjustment(convertLinearRgbToLab(c)));
        }
    });
    return out;
}

struct FeatureResponse {
    Plane edgeMagnitude, pointMagnitude;
};

FeatureResponse detectFeatures(const Plane& luminance, const FeatureFilters& f)
{
    // [FLIP, feature pipeline] responses along x and y, combined as the norm of the 2-vector.
    // The x responses share the smoothing along y, the y responses the smoothing along x.
    const Plane smoothY = detail::filterColumns(luminance, f.smooth);
    const Plane smoothX = detail::filterRows(luminance, f.smooth);
    const Plane ex = detail::filterRows(smoothY, f.edge);
    const Plane px = detail::filterRows(smoothY, f.point);
    const Plane ey = detail::filterColumns(smoothX, f.edge);
    const Plane py = detail::filterColumns(smoothX, f.point);
    FeatureResponse r{Plane(luminance.width, luminance.height),
                      Plane(luminance.width, luminance.height)};
    for (std::size_t i = 0; i < luminance.values.size(); ++i) {
        r.edgeMagnitude.values[i] = std::hypot(ex.values[i], ey.values[i]);
        r.pointMagnitude.values[i] = std::hypot(px.values[i], py.values[i]);
    }
    return r;
}

// [FLIP, color pipeline, color metric] map (HyAB)^qc to [0, 1]: [0, pc cmax) linearly onto
// [0, pt), [pc cmax, cmax] linearly onto [pt, 1].
double redistributeColorError(double powered, double cmax)
{
    const double knee = kPc * cmax;
    const double e = powered < knee ? kPt * powered / knee
                                    : kPt + (powered - knee) / (cmax - knee) * (1.0 - kPt);
    return std::min(e, 1.0);
}

Image<float> computeLdrFlipMap(const LinearRgbPlanes& test, const LinearRgbPlanes& reference,
                               const FlipKernels& k)
{
    const int w = test.r.width, h = test.r.height;
    Image<float> map(w, h);
    if (w == 0 || h == 0)
        return map;
    const PreparedImage pt = prepareImage(test, k);
    const PreparedImage pr = prepareImage(reference, k);
    const FeatureResponse ft = detectFeatures(pt.luminance, k.features);
    const FeatureResponse fr = detectFeatures(pr.luminance, k.features);
    detail::forEachRowBlock(h, [&](int y0, int y1) {
        for (std::size_t i = std::size_t(y0) * w; i < std::size_t(y1) * w; ++i) {
            // [FLIP, color pipeline, color metric] Delta E_c.
            const double hyab = computeHyab(glm::dvec3(pr.huntLab[i]), glm::dvec3(pt.huntLab[i]));
            const double colorError = redistributeColorError(std::pow(hyab, kQc), k.cmax);
            // [FLIP, feature pipeline] Delta E_f = (max(|edge_r - edge_t|, |point_r - point_t|)
            // / sqrt(2))^qf, in [0, 1].
            const double edgeDiff =
                std::abs(double(fr.edgeMagnitude.values[i]) - ft.edgeMagnitude.values[i]);
            const double pointDiff =
                std::abs(double(fr.pointMagnitude.values[i]) - ft.pointMagnitude.values[i]);
            const double featureError =
                std::pow(std::max(edgeDiff, pointDiff) / std::sqrt(2.0), kQf);
            // [FLIP, final error] Delta E = Delta E_c ^ (1 - Delta E_f).
            map.pixels[i] = float(std::pow(colorError, 1.0 - std::min(featureError, 1.0)));
        }
    });
    return map;
}

FlipResult finishFlip(Image<float> map, MaskView mask)
{
    FlipResult result;
    const auto mean = detail::computeWeightedMean(
        map.width, map.height, mask, [&](std::size_t i) { return double(map.pixels[i]); });
    result.mean = mean.mean;
    result.pixels = mean.pixels;
    result.map = std::move(map);
    return result;
}

// ------------------------------------------------------------------------------------------------
// HDR-FLIP

// [HDR-FLIP, tone mapping] tone mappers written as rational polynomials
// T(x) = (k0 x^2 + k1 x + k2) / (k3 x^2 + k4 x + k5).
struct RationalToneCurve {
    double k0, k1, k2, k3, k4, k5;
    double apply(double x) const { return (k0 * x * x + k1 * x + k2) / (k3 * x * x + k4 * x + k5); }
    // The x >= 0 with T(x) = t: the positive root of (k0 - t k3) x^2 + (k1 - t k4) x
    // + (k2 - t k5) = 0.
    double invert(double t) const
    {
        const double a = k0 - t * k3, b = k1 - t * k4, c = k2 - t * k5;
        if (std::abs(a) < 1e-15)
            return -c / b;
        const double disc = std::sqrt(std::max(0.0, b * b - 4 * a * c));
        const double r1 = (-b + disc) / (2 * a), r2 = (-b - disc) / (2 * a);
        return r1 >= 0 ? (r2 >= 0 ? std::min(r1, r2) : r1) : r2;
    }
};

// Narkowicz's ACES fit x (2.51 x + 0.03) / (x (2.43 x + 0.59) + 0.14), applied to 0.6 x.
RationalToneCurve makeAcesCurve()
{
    return {0.6 * 0.6 * 2.51, 0.6 * 0.03, 0.0, 0.6 * 0.6 * 2.43, 0.6 * 0.59, 0.14};
}

// Hable's filmic curve ((x (A x + C B) + D E) / (x (A x + B) + D F)) - E / F with A..F = 0.15,
// 0.50, 0.10, 0.20, 0.02, 0.30, as one rational polynomial, scaled by 1 / T(11.2) (white point)
// and applied to 2 x (exposure bias).
RationalToneCurve makeHableCurve()
{
    const double a = 0.15, b = 0.50, c = 0.10, d = 0.20, e = 0.02, f = 0.30, white = 11.2;
    RationalToneCurve t{a * f - a * e, c * b * f - b * e, 0.0, a * f, b * f, d * f * f};
    const double whiteScale = 1.0 / t.apply(white);
    return {
        4 * t.k0 * whiteScale, 2 * t.k1 * whiteScale, t.k2 * whiteScale, 4 * t.k3, 2 * t.k4, t.k5};
}

double computeLuminance(const glm::dvec3& c)
{
    return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z;
}

// [HDR-FLIP, exposure range] T^-1(0.85): the exposed value that the tone mapper maps to 0.85. The
// start exposure brings the reference's maximum luminance there, the stop exposure its median.
double invertToneMapper(ToneMapper toneMapper, double t)
{
    switch (toneMapper) {
    case ToneMapper::Aces:
        return makeAcesCurve().invert(t);
    case ToneMapper::Hable:
        return makeHableCurve().invert(t);
    case ToneMapper::Reinhard:
        return t / (1.0 - t); // x / (1 + x) = t
    }
    return t;
}

} // namespace

glm::vec3 applyToneMapper(ToneMapper toneMapper, const glm::vec3& exposedIn)
{
    const glm::dvec3 x = glm::max(glm::dvec3(exposedIn), glm::dvec3(0.0));
    glm::dvec3 y;
    switch (toneMapper) {
    case ToneMapper::Aces:
    case ToneMapper::Hable: {
        const RationalToneCurve t =
            toneMapper == ToneMapper::Aces ? makeAcesCurve() : makeHableCurve();
        for (int c = 0; c < 3; ++c)
            y[c] = std::isinf(x[c]) ? 1.0 : t.apply(x[c]);
        break;
    }
    case ToneMapper::Reinhard: {
        const double lum = computeLuminance(x);
        y = std::isinf(lum) ? glm::dvec3(1.0) : x / (1.0 + lum);
        break;
    }
    }
    return glm::vec3(glm::clamp(y, glm::dvec3(0.0), glm::dvec3(1.0)));
}

double computePixelsPerDegree(double distanceMeters, double widthMeters, double widthPixels)
{
    if (!(distanceMeters > 0) || !(widthMeters > 0) || !(widthPixels > 0))
        throw std::invalid_argument("computePixelsPerDegree: distance, width and pixel count "
                                    "must be > 0");
    // [FLIP, viewing conditions] pixels per degree = d (r / w) pi / 180.
    return distanceMeters * (widthPixels / widthMeters) * kPi / 180.0;
}

FlipResult computeFlip(const Image<glm::vec3>& test, const Image<glm::vec3>& reference,
                       ColorEncoding encoding, const FlipOptions& options, MaskView mask)
{
    detail::requireSameSize(test.width, test.height, reference.width, reference.height,
                            "computeFlip");
    detail::requireValidMask(mask, test.width, test.height, "computeFlip");
    detail::requireFiniteReference(reference, "computeFlip");
    const FlipKernels kernels = makeFlipKernels(options.pixelsPerDegree);
    Image<float> map = computeLdrFlipMap(convertToLinearPlanes(test, encoding),
                                         convertToLinearPlanes(reference, encoding), kernels);
    return finishFlip(std::move(map), mask);
}

FlipResult computeFlip(const Image<float>& test, const Image<float>& reference,
                       ColorEncoding encoding, const FlipOptions& options, MaskView mask)
{
    detail::requireSameSize(test.width, test.height, reference.width, reference.height,
                            "computeFlip");
    Image<glm::vec3> t(test.width, test.height), r(reference.width, reference.height);
    for (std::size_t i = 0; i < test.pixels.size(); ++i) {
        t.pixels[i] = glm::vec3(test.pixels[i]);
        r.pixels[i] = glm::vec3(reference.pixels[i]);
    }
    return computeFlip(t, r, encoding, options, mask);
}

FlipResult computeHdrFlip(const Image<glm::vec3>& test, const Image<glm::vec3>& reference,
                          const FlipOptions& options, MaskView mask)
{
    detail::requireSameSize(test.width, test.height, reference.width, reference.height,
                            "computeHdrFlip");
    detail::requireValidMask(mask, test.width, test.height, "computeHdrFlip");
    detail::requireFiniteReference(reference, "computeHdrFlip");
    const FlipKernels kernels = makeFlipKernels(options.pixelsPerDegree);
    const int w = test.width, h = test.height;
    const std::size_t n = test.pixels.size();

    // [HDR-FLIP, exposure range] from the reference's luminance.
    double start = 0, stop = 0;
    if (!options.startExposure || !options.stopExposure) {
        std::vector<double> lum(n);
        double maxLum = 0;
        for (std::size_t i = 0; i < n; ++i) {
            lum[i] = computeLuminance(glm::max(glm::dvec3(reference.pixels[i]), glm::dvec3(0.0)));
            maxLum = std::max(maxLum, lum[i]);
        }
        if (maxLum > 0) {
            const double target = invertToneMapper(options.toneMapper, 0.85);
            std::nth_element(lum.begin(), lum.begin() + std::ptrdiff_t(n / 2), lum.end());
            double median = lum[n / 2];
            if (!(median > 0)) {
                // More than half the reference is black: the median of the lit pixels instead
                // (the paper's formula would give an infinite stop exposure).
                std::vector<double> lit;
                for (double v : lum)
                    if (v > 0)
                        lit.push_back(v);
                std::nth_element(lit.begin(), lit.begin() + std::ptrdiff_t(lit.size() / 2),
                                 lit.end());
                median = lit[lit.size() / 2];
            }
            start = std::log2(target / maxLum);
            stop = std::log2(target / median);
        }
    }
    if (options.startExposure)
        start = *options.startExposure;
    if (options.stopExposure)
        stop = *options.stopExposure;
    if (!std::isfinite(start) || !std::isfinite(stop) || start > stop)
        throw std::invalid_argument("computeHdrFlip: need finite exposures with start <= stop, "
                                    "got " +
                                    std::to_string(start) + " and " + std::to_string(stop));
    int count = 1;
    if (options.exposureCount)
        count = *options.exposureCount;
    else if (stop > start)
        count = std::max(2, int(std::ceil(stop - start)));
    if (count < 1)
        throw std::invalid_argument("computeHdrFlip: exposureCount must be >= 1");

    Image<float> hdrMap(w, h, 0.0f);
    Image<glm::vec3> exposedTest(w, h), exposedRef(w, h);
    for (int e = 0; e < count; ++e) {
        const double exposure = count > 1 ? start + e * (stop - start) / (count - 1) : start;
        const double scale = std::exp2(exposure);
        // [HDR-FLIP, tone mapping] expose by 2^c and tone map both images, then LDR-FLIP on the
        // result (linear values in [0, 1]).
        for (std::size_t i = 0; i < n; ++i) {
            exposedTest.pixels[i] =
                applyToneMapper(options.toneMapper, glm::vec3(scale * glm::dvec3(test.pixels[i])));
            exposedRef.pixels[i] = applyToneMapper(
                options.toneMapper, glm::vec3(scale * glm::dvec3(reference.pixels[i])));
        }
        const Image<float> map =
            computeLdrFlipMap(convertToLinearPlanes(exposedTest, ColorEncoding::Linear),
                              convertToLinearPlanes(exposedRef, ColorEncoding::Linear), kernels);
        // [HDR-FLIP, combination] the HDR-FLIP map is the per-pixel maximum over the exposures
        // (written so that a NaN propagates).
        for (std::size_t i = 0; i < n; ++i) {
            const float v = map.pixels[i];
            if (e == 0 || std::isnan(v) || v > hdrMap.pixels[i])
                hdrMap.pixels[i] = v;
        }
    }
    FlipResult result = finishFlip(std::move(hdrMap), mask);
    result.startExposure = start;
    result.stopExposure = stop;
    result.exposureCount = count;
    return result;
}

} // namespace rtlab::metrics
