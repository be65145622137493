#include "families/voxel_gi/upsample.h"

#include "core/error.h"

#include <glm/geometric.hpp>

#include <algorithm>
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

Image<glm::vec3> upsampleIrradiance(const Image<glm::vec3>& low, const ReducedGBuffer& reduced,
                                    const scene::GBuffer& full)
{
    const int f = reduced.factor;
    if (f == 1)
        return low;
    const int lw = reduced.gbuffer.width, lh = reduced.gbuffer.height;
    if (low.width != lw || low.height != lh)
        throw Error("reduced gather: irradiance of " + std::to_string(low.width) + "x" +
                    std::to_string(low.height) + " for a reduced G-buffer of " +
                    std::to_string(lw) + "x" + std::to_string(lh));
    Image<glm::vec3> out(full.width, full.height, glm::vec3(0.0f));
    // Geometric similarity of low-resolution sample s to the pixel at p with normal n and view
    // depth d: distance of s from the pixel's tangent plane against 2 % of the depth, and the
    // normals' agreement (cos^8).
    const auto similarity = [&](int s, const glm::vec3& p, const glm::vec3& n, float d) {
        const int r = reduced.representative[std::size_t(s)];
        if (r < 0)
            return 0.0f;
        const int rx = r % full.width, ry = r / full.width;
        const float plane = std::abs(glm::dot(n, full.position.at(rx, ry) - p)) /
                            std::max(0.02f * d, 1e-6f);
        const float c = std::max(0.0f, glm::dot(n, full.normal.at(rx, ry)));
        const float c2 = c * c, c4 = c2 * c2;
        return std::exp(-plane * plane) * c4 * c4;
    };
    for (int y = 0; y < full.height; ++y)
        for (int x = 0; x < full.width; ++x) {
            if (!full.hasSurface(x, y))
                continue;
            const glm::vec3 p = full.position.at(x, y), n = full.normal.at(x, y);
            const float d = std::isfinite(full.depth.at(x, y)) ? full.depth.at(x, y) : 1.0f;
            const float u = (x + 0.5f) / float(f) - 0.5f, v = (y + 0.5f) / float(f) - 0.5f;
            const int i0 = int(std::floor(u)), j0 = int(std::floor(v));
            const float fu = u - float(i0), fv = v - float(j0);
            glm::vec3 sum(0.0f);
            float weights = 0.0f;
            for (int dj = 0; dj <= 1; ++dj)
                for (int di = 0; di <= 1; ++di) {
                    const int i = std::clamp(i0 + di, 0, lw - 1), j = std::clamp(j0 + dj, 0, lh - 1);
                    const float bilinear = (di ? fu : 1.0f - fu) * (dj ? fv : 1.0f - fv);
                    const int s = j * lw + i;
                    const float w = bilinear * similarity(s, p, n, d);
                    sum += w * low.pixels[std::size_t(s)];
                    weights += w;
                }
            if (weights > 1e-6f) {
                out.at(x, y) = sum / weights;
                continue;
            }
            // No neighbour alike: the most similar of the 3 x 3 around, else the nearest with a
            // surface.
            const int ci = std::clamp(x / f, 0, lw - 1), cj = std::clamp(y / f, 0, lh - 1);
            float best = -1.0f;
            int bestSample = -1;
            for (int j = std::max(0, cj - 1); j <= std::min(lh - 1, cj + 1); ++j)
                for (int i = std::max(0, ci - 1); i <= std::min(lw - 1, ci + 1); ++i) {
                    const int s = j * lw + i;
                    if (reduced.representative[std::size_t(s)] < 0)
                        continue;
                    const float w = similarity(s, p, n, d) - 1e-3f * float(std::abs(i - ci) + std::abs(j - cj));
                    if (w > best) {
                        best = w;
                        bestSample = s;
                    }
                }
            if (bestSample >= 0)
                out.at(x, y) = low.pixels[std::size_t(bestSample)];
        }
    return out;
}

} // namespace rtlab::voxelgi
