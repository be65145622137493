// The plain C++ path. Every float operation of shadePixel happens in the same order as in
// shaders/bentcone_ssdo.comp (and this file is compiled with -ffp-contract=off, the shader marks
// its arithmetic `precise`), so the occlusion tests of both paths classify samples alike.

#include "bentcone_ssdo_cpu.h"

#include "scene/sky.h"

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "gpu/resources.h"
#include <cmath>

#include <limits>
#include <numbers>

namespace rtlab::bentcone_ssdo {

FrameSetup makeFrameSetup(const Settings& settings, const std::vector<glm::vec4>& pattern,
                          const std::vector<glm::vec4>& apertureTable,
                          const plugin::OcclusionInput& input)
{
    FrameSetup frame;
    frame.settings = settings;
    // The size of whichever view the technique reads: the GPU images when it binds them.
    const bool onGpu =
        input.gpu != nullptr && input.gpuLinearDepth != nullptr && input.gpuNormal != nullptr;
    frame.width = onGpu ? int(input.gpuLinearDepth->getDesc().width) : input.linearDepth->width;
    frame.height = onGpu ? int(input.gpuLinearDepth->getDesc().height) : input.linearDepth->height;
    frame.projection =
        plugin::ScreenProjection::fromMatrix(input.projection, frame.width, frame.height);
    frame.pattern = pattern;
    frame.apertureTable = apertureTable;
    frame.rotations = makeCellRotations(input.frameIndex);
    // The 16 world-space cone directions in view space (the view matrix may scale; normalise).
    const glm::dmat3 rotation(glm::dmat4(input.view));
    const auto& directions = scene::getConeDirections();
    for (int i = 0; i < kConeCount; ++i) {
        const glm::dvec3 d = rotation * directions[std::size_t(i)];
        const double length = glm::length(d);
        frame.coneDirections[std::size_t(i)] =
            length > 0.0 ? glm::vec3(d / length) : glm::vec3(0.0f, 0.0f, 1.0f);
    }
    return frame;
}

bool isSurfaceDepth(float depth)
{
    return depth > 0.0f && depth < std::numeric_limits<float>::max();
}

namespace {

//! Weight of one sample in the SH projection: pi / N (cosine-distributed directions).
float getShWeight(int sampleCount)
{
    return float(std::numbers::pi / sampleCount);
}

PixelResult makeNoSurfaceResult()
{
    PixelResult result;
    result.coneVisibility.fill(1.0f);
    return result;
}

} // namespace

PixelResult shadePixel(const FrameSetup& frame, const Image<float>& depth,
                       const Image<glm::vec3>& normal, int x, int y)
{
    const Settings& settings = frame.settings;
    const float centreDepth = depth.at(x, y);
    const glm::vec3 normalIn = normal.at(x, y);
    const float length2 =
        normalIn.x * normalIn.x + normalIn.y * normalIn.y + normalIn.z * normalIn.z;
    if (!isSurfaceDepth(centreDepth) || !(length2 > 1e-12f && length2 < 1e30f))
        return makeNoSurfaceResult();
    const float inverseLength = 1.0f / std::sqrt(length2);
    const glm::vec3 n(normalIn.x * inverseLength, normalIn.y * inverseLength,
                      normalIn.z * inverseLength);
    const glm::vec3 p =
        frame.projection.toView(glm::vec2(float(x) + 0.5f, float(y) + 0.5f), centreDepth);

    // Tangent frame around n [Duff et al. 2017], turned by the pixel's cell rotation
    // (interleaved sampling [Keller & Heidrich 2001]).
    const float sign = n.z >= 0.0f ? 1.0f : -1.0f;
    const float a = -1.0f / (sign + n.z);
    const float b = n.x * n.y * a;
    const glm::vec3 t(1.0f + sign * n.x * n.x * a, sign * b, -sign * n.x);
    const glm::vec3 bt(b, sign + n.y * n.y * a, -n.y);
    const glm::vec2 rotation = frame.rotations[std::size_t(getCellIndex(x, y))];
    const glm::vec3 tr(rotation.x * t.x + rotation.y * bt.x, rotation.x * t.y + rotation.y * bt.y,
                       rotation.x * t.z + rotation.y * bt.z);
    const glm::vec3 br(rotation.x * bt.x - rotation.y * t.x, rotation.x * bt.y - rotation.y * t.y,
                       rotation.x * bt.z - rotation.y * t.z);

    const float radius = settings.radius;
    const float bias = settings.depthBias;
    const float width = float(frame.width), height = float(frame.height);
    const int sampleCount = int(frame.pattern.size());
    float visible = 0.0f;
    glm::vec3 sum(0.0f); // unoccluded pattern directions, in the turned tangent frame
    for (int k = 0; k < sampleCount; ++k) {
        const glm::vec4 s = frame.pattern[std::size_t(k)];
        // [Klehm et al. 2011]: the sample point in the hemisphere of radius r.
        const float len = radius * s.w;
        const float ox = s.x * len, oy = s.y * len, oz = s.z * len;
        const glm::vec3 q(p.x + ((ox * tr.x + oy * br.x) + oz * n.x),
                          p.y + ((ox * tr.y + oy * br.y) + oz * n.y),
                          p.z + ((ox * tr.z + oy * br.z) + oz * n.z));
        const float sampleDepth = -q.z;
        bool occluded = false;
        if (sampleDepth > 0.0f) {
            const glm::vec2 pixel = frame.projection.toPixel(q);
            if (pixel.x >= 0.0f && pixel.y >= 0.0f && pixel.x < width && pixel.y < height) {
                const int ix = int(pixel.x), iy = int(pixel.y);
                const float bufferDepth = depth.at(ix, iy);
                if (isSurfaceDepth(bufferDepth)) {
                    // Occluded when the depth buffer lies in front of the sample by more than
                    // the bias, and by less than the radius (range check: a surface far in
                    // front belongs to another object and does not occlude), and the buffer's
                    // point lies above the tangent plane at p (a point of p's own plane, found
                    // through a neighbouring pixel centre at a grazing angle, never occludes).
                    const float difference = sampleDepth - bufferDepth;
                    const glm::vec3 o = frame.projection.toView(
                        glm::vec2(float(ix) + 0.5f, float(iy) + 0.5f), bufferDepth);
                    const float aboveTangent =
                        ((o.x - p.x) * n.x + (o.y - p.y) * n.y) + (o.z - p.z) * n.z;
                    occluded = difference > bias * sampleDepth && difference < radius &&
                               aboveTangent > bias * centreDepth;
                }
            }
        }
        if (!occluded) {
            visible += 1.0f;
            sum.x += s.x;
            sum.y += s.y;
            sum.z += s.z;
        }
    }

    PixelResult result;
    result.hasSurface = true;
    result.visibleSamples = int(visible);
    // [Tomorrow Children talk]: project onto 2-band SH instead of a scalar. The sum of the
    // cosine-distributed unoccluded directions times pi / N estimates Int V cos w dw.
    const glm::vec3 bent(sum.x * tr.x + sum.y * br.x + sum.z * n.x,
                         sum.x * tr.y + sum.y * br.y + sum.z * n.y,
                         sum.x * tr.z + sum.y * br.z + sum.z * n.z);
    const float weight = getShWeight(sampleCount);
    result.sh = glm::vec4(weight * kShY00 * visible, weight * kShY1 * bent.y,
                          weight * kShY1 * bent.z, weight * kShY1 * bent.x);
    // A = L00 / (pi Y00) = visible / N, computed in the exact form so that no occluder gives 1;
    // its cone (aperture, cos, sin, versine) comes from the table of the N + 1 possible counts.
    const float ambient = visible / float(sampleCount);
    const glm::vec4 entry = frame.apertureTable[std::size_t(result.visibleSamples)];
    const Cap bentCap{entry.x, entry.y, entry.z, entry.w};
    const glm::vec3 l1(result.sh.w, result.sh.y, result.sh.z);
    const float l1Length2 = l1.x * l1.x + l1.y * l1.y + l1.z * l1.z;
    glm::vec3 axis = n; // nothing visible: the reference's convention
    if (l1Length2 > 0.0f) {
        const float inverse = 1.0f / std::sqrt(l1Length2);
        axis = glm::vec3(l1.x * inverse, l1.y * inverse, l1.z * inverse);
    }
    result.ambient = ambient;
    result.bentNormal = axis;
    result.aperture = bentCap.angle;
    for (int i = 0; i < kConeCount; ++i)
        result.coneVisibility[std::size_t(i)] = computeConeVisibility(
            frame.coneDirections[std::size_t(i)], axis, bentCap, n, settings.coneIntersection);
    return result;
}

void computeOnCpu(const FrameSetup& frame, const plugin::OcclusionInput& input,
                  plugin::OcclusionOutput& out)
{
    const int w = frame.width, h = frame.height;
    out.ambient = Image<float>(w, h, 1.0f);
    out.bentNormal = Image<glm::vec3>(w, h, glm::vec3(0.0f));
    out.coneAperture = Image<float>(w, h, 0.0f);
    out.coneVisibility.assign(std::size_t(kConeCount), Image<float>(w, h, 1.0f));
    tbb::parallel_for(tbb::blocked_range<int>(0, h), [&](const tbb::blocked_range<int>& rows) {
        for (int y = rows.begin(); y < rows.end(); ++y) {
            for (int x = 0; x < w; ++x) {
                const PixelResult r = shadePixel(frame, *input.linearDepth, *input.normal, x, y);
                out.ambient.at(x, y) = r.ambient;
                out.bentNormal.at(x, y) = r.bentNormal;
                out.coneAperture.at(x, y) = r.aperture;
                for (int i = 0; i < kConeCount; ++i)
                    out.coneVisibility[std::size_t(i)].at(x, y) = r.coneVisibility[std::size_t(i)];
            }
        }
    });
}

} // namespace rtlab::bentcone_ssdo
