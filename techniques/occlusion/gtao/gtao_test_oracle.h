#pragma once
// An independent reference for the GTAO tests on a floor (y = 0) in front of an infinite wall
// (x = wallX), in double precision and world space. It integrates the same slice form of the
// cosine-weighted visibility as GTAO, but with exact horizons (bisection on ray casts against the
// wall) and numerical quadrature instead of the closed forms, and it derives the tolerances of a
// GTAO estimate with N slices and S steps:
//  * sliceError: the worst error of the N-slice rule over every rotation of the slice set
//    (the ratio sum(visible) / sum(unoccluded), as GTAO with normalize computes it);
//  * stepError: the worst, over rotations, error the N-slice ratio can take from horizons found
//    too low. On a side with horizon h the samples can miss at most the angle dh between the
//    horizon point and the wall point one step (plus one pixel of bilinear support) before it
//    along the slice's screen line (never more than the occluded arc). The side's visibility
//    |n_p| a(h) then moves by at most |n_p| (|a'(h)| dh + dh^2), a'(t) = sin(t) cos(t - gamma),
//    |a''| <= 1; these bounds are summed over the N slices of a set and divided by the set's
//    unoccluded sum, as the ratio is.
//  * horizonStepError: the largest dh itself (radians), for the bent normal.

#include "gtao_test_scene.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <numbers>
#include <stdexcept>

namespace rtlab::occlusion::test {

struct WallOracleSettings {
    double wallX = 2.0;
    double radius = 1.0;       //!< may be +inf
    bool clipToScreen = false; //!< occluders count only where they project inside the image
    int slices = 32;           //!< N of the GTAO estimate whose tolerance is derived
    int steps = 64;            //!< S of that estimate
    double maxPixelRadius = 4096.0;
    int rotations = 16; //!< rotations of the slice set tried for sliceError
};

struct WallOracleResult {
    double ambient = 1.0;          //!< the integral (fine slice quadrature)
    glm::dvec3 bentNormal{0.0};    //!< world space, unit
    double bentLength = 0.0;       //!< length of the mean bent vector (2/3 when unoccluded)
    double sliceError = 0.0;       //!< max over rotations |N-slice ratio - ambient|
    double bentSliceError = 0.0;   //!< radians, the same for the bent normal's direction
    double stepError = 0.0;        //!< bound on the ambient error from the step discretisation
    double horizonStepError = 0.0; //!< radians: the largest dh
};

class WallOracle {
public:
    WallOracle(const TestGBuffer& g, const scene::Camera& camera, WallOracleSettings settings)
        : mG(g), mCamera(camera), mS(settings), mProjection(plugin::ScreenProjection::fromMatrix(
                                                    g.projection, g.depth.width, g.depth.height))
    {
    }

    //! The reference at floor pixel (x, y).
    WallOracleResult evaluate(int x, int y) const
    {
        const glm::dvec3 p = mG.worldPosition.at(x, y);
        const glm::dvec3 n(0.0, 1.0, 0.0);
        const glm::dvec3 v = glm::normalize(glm::dvec3(mCamera.position) - p);
        glm::dvec3 t1 = glm::normalize(glm::cross(v, glm::dvec3(0.0, 0.0, 1.0)));
        const glm::dvec3 t2 = glm::cross(v, t1);
        const int n0 = mS.slices, k0 = mS.rotations;
        std::vector<Slice> slices(std::size_t(n0) * k0);
        for (int i = 0; i < n0 * k0; ++i) {
            const double phi = std::numbers::pi * double(i) / double(n0 * k0);
            slices[std::size_t(i)] =
                evaluateSlice(p, n, v, std::cos(phi) * t1 + std::sin(phi) * t2);
        }
        WallOracleResult r;
        double visible = 0.0, full = 0.0;
        glm::dvec3 bentOccluded(0.0);
        for (const Slice& s : slices) {
            visible += s.visible;
            full += s.full;
            bentOccluded += s.bentFull - s.bentVisible;
            r.horizonStepError = std::max(r.horizonStepError, s.horizonStepError);
        }
        r.ambient = visible / full;
        const double m = double(slices.size());
        const glm::dvec3 bent = (2.0 / 3.0) * n - bentOccluded / m;
        r.bentNormal = glm::normalize(bent);
        r.bentLength = glm::length(bent);
        for (int k = 0; k < k0; ++k) { // slice set i * k0 + k, i = 0..N-1
            double vis = 0.0, ful = 0.0, step = 0.0;
            glm::dvec3 occ(0.0);
            for (int i = 0; i < n0; ++i) {
                const Slice& s = slices[std::size_t(i * k0 + k)];
                vis += s.visible;
                ful += s.full;
                step += s.stepBound;
                occ += s.bentFull - s.bentVisible;
            }
            r.sliceError = std::max(r.sliceError, std::abs(vis / ful - r.ambient));
            r.stepError = std::max(r.stepError, step / ful);
            const glm::dvec3 b = glm::normalize((2.0 / 3.0) * n - occ / double(n0));
            r.bentSliceError = std::max(
                r.bentSliceError, std::acos(std::clamp(glm::dot(b, r.bentNormal), -1.0, 1.0)));
        }
        return r;
    }

private:
    struct Slice {
        double visible = 0.0, full = 0.0;
        glm::dvec3 bentVisible{0.0}, bentFull{0.0};
        double stepBound = 0.0;        //!< |n_p| sum over sides (|a'(h)| dh + dh^2)
        double horizonStepError = 0.0; //!< max dh over the sides
    };

    glm::dvec3 toView(const glm::dvec3& world) const
    {
        return glm::dvec3(glm::dmat4(mG.view) * glm::dvec4(world, 1.0));
    }
    glm::dvec2 toPixel(const glm::dvec3& world) const
    {
        const glm::dvec3 q = toView(world);
        const glm::dvec2 s(mProjection.scale), o(mProjection.offset), size(mProjection.size);
        return (glm::dvec2(q.x * s.x / -q.z - o.x, q.y * s.y / -q.z - o.y) + 1.0) * 0.5 * size;
    }
    bool isInsideImage(const glm::dvec2& pixel) const
    {
        const glm::dvec2 size(mProjection.size);
        return pixel.x >= 0.5 && pixel.y >= 0.5 && pixel.x <= size.x - 0.5 &&
               pixel.y <= size.y - 0.5;
    }
    //! Wall hit of the ray p + t w that counts as an occluder (within the radius, on screen).
    bool hitsWall(const glm::dvec3& p, const glm::dvec3& w, glm::dvec3* hit = nullptr) const
    {
        if (w.x <= 0.0)
            return false;
        const double t = (mS.wallX - p.x) / w.x;
        const glm::dvec3 q = p + t * w;
        if (!(t > 0.0) || q.y < 0.0 || !(t <= mS.radius))
            return false;
        if (mS.clipToScreen && (toView(q).z >= 0.0 || !isInsideImage(toPixel(q))))
            return false;
        if (hit)
            *hit = q;
        return true;
    }

    //! Simpson's rule on [a, b] (the integrands are smooth on each side of 0).
    static double integrate(const std::function<double(double)>& f, double a, double b)
    {
        const int n = 64;
        const double h = (b - a) / n;
        double sum = f(a) + f(b);
        for (int i = 1; i < n; ++i)
            sum += f(a + i * h) * (i % 2 == 1 ? 4.0 : 2.0);
        return sum * h / 3.0;
    }

    Slice evaluateSlice(const glm::dvec3& p, const glm::dvec3& n, const glm::dvec3& v,
                        const glm::dvec3& s) const
    {
        Slice out;
        const double ns = glm::dot(n, s), nv = glm::dot(n, v);
        const double w = std::sqrt(ns * ns + nv * nv);
        const double gamma = std::atan2(ns, nv);
        const auto dirAt = [&](double theta) { return std::sin(theta) * s + std::cos(theta) * v; };
        double horizon[2];
        for (int side = 0; side < 2; ++side) {
            const double sign = side == 0 ? 1.0 : -1.0;
            const double boundary = gamma + sign * 0.5 * std::numbers::pi;
            // Occluded directions form [theta*, boundary] (checked on a grid): bisect theta*.
            const auto occluded = [&](double theta) { return hitsWall(p, dirAt(theta)); };
            const double nearBoundary = boundary - sign * 1e-9;
            bool seen = false;
            for (int j = 0; j <= 16; ++j) {
                const bool o = occluded(nearBoundary * j / 16.0);
                if (seen && !o)
                    throw std::logic_error("oracle: occluded directions are not one interval");
                seen = seen || o;
            }
            if (!occluded(nearBoundary)) {
                horizon[side] = boundary;
                continue;
            }
            double lo = 0.0, hi = nearBoundary;
            for (int it = 0; it < 60; ++it) {
                const double mid = 0.5 * (lo + hi);
                (occluded(mid) ? hi : lo) = mid;
            }
            horizon[side] = hi;
            const double dh = computeStepError(p, dirAt(hi), boundary - hi);
            out.horizonStepError = std::max(out.horizonStepError, dh);
            out.stepBound += w * (std::abs(std::sin(hi) * std::cos(hi - gamma)) * dh + dh * dh);
        }
        const auto cosine = [&](double t) { return std::cos(t - gamma) * std::abs(std::sin(t)); };
        const auto arc = [&](double lo, double hi) {
            return integrate(cosine, lo, 0.0) + integrate(cosine, 0.0, hi);
        };
        const auto arcVector = [&](double lo, double hi) {
            const auto fs = [&](double t) { return cosine(t) * std::sin(t); };
            const auto fv = [&](double t) { return cosine(t) * std::cos(t); };
            return (integrate(fs, lo, 0.0) + integrate(fs, 0.0, hi)) * s +
                   (integrate(fv, lo, 0.0) + integrate(fv, 0.0, hi)) * v;
        };
        const double half = 0.5 * std::numbers::pi;
        out.visible = w * arc(horizon[1], horizon[0]);
        out.full = w * arc(gamma - half, gamma + half);
        out.bentVisible = w * arcVector(horizon[1], horizon[0]);
        out.bentFull = w * arcVector(gamma - half, gamma + half);
        return out;
    }

    //! Angle at p between the horizon point and the wall point one step plus one pixel before it
    //! on the slice's screen line; at most the occluded arc `arc` of that side.
    double computeStepError(const glm::dvec3& p, const glm::dvec3& horizonDir, double arc) const
    {
        glm::dvec3 q;
        if (!hitsWall(p, horizonDir, &q))
            return std::abs(arc);
        const glm::dvec2 pp = toPixel(p), pq = toPixel(q);
        const double extent = computeExtent(p, q);
        const double delta = std::max(extent - 1.0, 0.0) / mS.steps + 1.0;
        const glm::dvec2 back = pq - delta * glm::normalize(pq - pp);
        // The camera ray through `back` and its wall point.
        const glm::dvec3 viewPoint(mProjection.toView(glm::vec2(back), 1.0f));
        const glm::dvec3 dir = glm::inverse(glm::dmat3(glm::dmat4(mG.view))) * viewPoint;
        const glm::dvec3 cam(mCamera.position);
        const double t = (mS.wallX - cam.x) / dir.x;
        const glm::dvec3 q2 = cam + t * dir;
        if (!(t > 0.0) || q2.y < 0.0)
            return std::abs(arc);
        const double angle = std::acos(
            std::clamp(glm::dot(glm::normalize(q - p), glm::normalize(q2 - p)), -1.0, 1.0));
        return std::min(angle, std::abs(arc));
    }

    //! GTAO's search extent (sphere mode) along the screen line from p toward q.
    double computeExtent(const glm::dvec3& p, const glm::dvec3& q) const
    {
        const glm::dvec3 pv = toView(p);
        const double sinAngle = mS.radius / glm::length(pv);
        if (!(sinAngle < 1.0))
            return mS.maxPixelRadius;
        const glm::dvec3 u = glm::normalize(pv);
        glm::dvec3 s = toView(q) - pv;
        s = glm::normalize(s - glm::dot(s, u) * u); // in the slice plane, orthogonal to u
        const glm::dvec3 tangent = std::sqrt(1.0 - sinAngle * sinAngle) * u + sinAngle * s;
        if (!(tangent.z < 0.0))
            return mS.maxPixelRadius;
        const glm::dvec2 scale(mProjection.scale), size(mProjection.size);
        const glm::dvec2 offset =
            0.5 * size * scale *
            (glm::dvec2(tangent.x, tangent.y) / -tangent.z - glm::dvec2(pv.x, pv.y) / -pv.z);
        return std::min(glm::length(offset), mS.maxPixelRadius);
    }

    const TestGBuffer& mG;
    scene::Camera mCamera;
    WallOracleSettings mS;
    plugin::ScreenProjection mProjection;
};

} // namespace rtlab::occlusion::test
