// The standard evaluation masks: depth edges, screen border, thin structures.
#include "metrics/image_metrics.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <unordered_set>

namespace rtlab::metrics {

namespace {

void requireNonNegative(int k, const char* what, const char* name)
{
    if (k < 0)
        throw std::invalid_argument(std::string(what) + ": " + name + " must be >= 0, got " +
                                    std::to_string(k));
}

// Separable max filter over a (2k+1) x (2k+1) square, clipped at the image edge.
Image<std::uint8_t> dilateSquare(const Image<std::uint8_t>& in, int k)
{
    const int w = in.width, h = in.height;
    if (k == 0 || w == 0 || h == 0) {
        Image<std::uint8_t> out(w, h);
        for (std::size_t i = 0; i < in.pixels.size(); ++i)
            out.pixels[i] = in.pixels[i] != 0 ? 1 : 0;
        return out;
    }
    // Distance to the nearest set pixel along each row (clipped at k + 1), then along columns:
    // a pixel is within Chebyshev distance k of a set pixel iff some pixel of its column window
    // has a row-distance <= k.
    Image<std::uint8_t> rows(w, h), out(w, h);
    for (int y = 0; y < h; ++y) {
        int last = -(k + 1) - 1; // position of the last set pixel seen from the left
        auto fromLeft = std::vector<int>(std::size_t(w));
        auto fromRight = std::vector<int>(std::size_t(w));
        for (int x = 0; x < w; ++x) {
            if (in.at(x, y) != 0)
                last = x;
            fromLeft[std::size_t(x)] = x - last;
        }
        last = w + k + 1;
        for (int x = w - 1; x >= 0; --x) {
            if (in.at(x, y) != 0)
                last = x;
            fromRight[std::size_t(x)] = last - x;
        }
        for (int x = 0; x < w; ++x)
            rows.at(x, y) =
                std::min(fromLeft[std::size_t(x)], fromRight[std::size_t(x)]) <= k ? 1 : 0;
    }
    for (int x = 0; x < w; ++x) {
        int last = -(k + 1) - 1;
        auto fromTop = std::vector<int>(std::size_t(h));
        auto fromBottom = std::vector<int>(std::size_t(h));
        for (int y = 0; y < h; ++y) {
            if (rows.at(x, y) != 0)
                last = y;
            fromTop[std::size_t(y)] = y - last;
        }
        last = h + k + 1;
        for (int y = h - 1; y >= 0; --y) {
            if (rows.at(x, y) != 0)
                last = y;
            fromBottom[std::size_t(y)] = last - y;
        }
        for (int y = 0; y < h; ++y)
            out.at(x, y) =
                std::min(fromTop[std::size_t(y)], fromBottom[std::size_t(y)]) <= k ? 1 : 0;
    }
    return out;
}

// A valid surface depth (> 0 and finite); anything else is background.
inline bool isSurface(float d)
{
    return std::isfinite(d) && d > 0;
}

bool isDiscontinuity(float a, float b, double relativeJump)
{
    const bool sa = isSurface(a), sb = isSurface(b);
    if (!sa && !sb)
        return false;
    if (sa != sb)
        return true;
    return std::abs(double(a) - double(b)) / std::min(double(a), double(b)) > relativeJump;
}

} // namespace

Image<std::uint8_t> dilateMask(const Image<std::uint8_t>& mask, int k)
{
    requireNonNegative(k, "dilateMask", "k");
    return dilateSquare(mask, k);
}

Image<std::uint8_t> makeDepthEdgeMask(const Image<float>& depth, int k, double relativeJump)
{
    requireNonNegative(k, "makeDepthEdgeMask", "k");
    if (!(relativeJump > 0) || !std::isfinite(relativeJump))
        throw std::invalid_argument("makeDepthEdgeMask: relativeJump must be finite and > 0, got " +
                                    std::to_string(relativeJump));
    const int w = depth.width, h = depth.height;
    Image<std::uint8_t> marks(w, h, 0);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            // Each 4-neighbour pair once: right and down.
            if (x + 1 < w && isDiscontinuity(depth.at(x, y), depth.at(x + 1, y), relativeJump))
                marks.at(x, y) = marks.at(x + 1, y) = 1;
            if (y + 1 < h && isDiscontinuity(depth.at(x, y), depth.at(x, y + 1), relativeJump))
                marks.at(x, y) = marks.at(x, y + 1) = 1;
        }
    return dilateSquare(marks, k);
}

Image<std::uint8_t> makeBorderMask(int width, int height, int k)
{
    requireNonNegative(k, "makeBorderMask", "k");
    if (width < 0 || height < 0)
        throw std::invalid_argument("makeBorderMask: negative image size");
    Image<std::uint8_t> mask(width, height, 0);
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x)
            mask.at(x, y) = std::min({x, y, width - 1 - x, height - 1 - y}) < k ? 1 : 0;
    return mask;
}

Image<std::uint8_t> makeThinStructureMask(const Image<std::uint32_t>& objectIds, int r,
                                          std::uint32_t background)
{
    if (r < 1)
        throw std::invalid_argument("makeThinStructureMask: r must be >= 1, got " +
                                    std::to_string(r));
    const int w = objectIds.width, h = objectIds.height;
    // Erosion: a square of side 2r+1 centred at c (clipped at the image edge) is "uniform" when
    // all its pixels carry c's id. Rows first: is the clipped row segment [x-r, x+r] uniform?
    Image<std::uint8_t> rowUniform(w, h, 0), uniform(w, h, 0);
    for (int y = 0; y < h; ++y) {
        // runStart/runEnd: the extent of the run of equal ids around x.
        auto runStart = std::vector<int>(std::size_t(w));
        auto runEnd = std::vector<int>(std::size_t(w));
        for (int x = 0; x < w; ++x)
            runStart[std::size_t(x)] = x > 0 && objectIds.at(x - 1, y) == objectIds.at(x, y)
                                           ? runStart[std::size_t(x - 1)]
                                           : x;
        for (int x = w - 1; x >= 0; --x)
            runEnd[std::size_t(x)] = x + 1 < w && objectIds.at(x + 1, y) == objectIds.at(x, y)
                                         ? runEnd[std::size_t(x + 1)]
                                         : x;
        for (int x = 0; x < w; ++x)
            rowUniform.at(x, y) = runStart[std::size_t(x)] <= std::max(0, x - r) &&
                                          runEnd[std::size_t(x)] >= std::min(w - 1, x + r)
                                      ? 1
                                      : 0;
    }
    // Columns: every row segment of the square is uniform and carries the centre's id.
    for (int x = 0; x < w; ++x)
        for (int y = 0; y < h; ++y) {
            const std::uint32_t id = objectIds.at(x, y);
            if (id == background)
                continue;
            bool ok = true;
            for (int j = std::max(0, y - r); j <= std::min(h - 1, y + r) && ok; ++j)
                ok = rowUniform.at(x, j) != 0 && objectIds.at(x, j) == id;
            uniform.at(x, y) = ok ? 1 : 0;
        }
    // Dilation of the eroded centres by the same square is the opening: a pixel survives when a
    // uniform square covers it (that square then carries the pixel's own id).
    const Image<std::uint8_t> opened = dilateSquare(uniform, r);
    Image<std::uint8_t> thin(w, h, 0);
    for (std::size_t i = 0; i < thin.pixels.size(); ++i)
        thin.pixels[i] = objectIds.pixels[i] != background && opened.pixels[i] == 0 ? 1 : 0;
    return thin;
}

Image<std::uint8_t> makeThinStructureMask(const Image<std::uint8_t>& coverage, int r)
{
    Image<std::uint32_t> ids(coverage.width, coverage.height);
    for (std::size_t i = 0; i < ids.pixels.size(); ++i)
        ids.pixels[i] = coverage.pixels[i] != 0 ? 1u : 0u;
    return makeThinStructureMask(ids, r, 0u);
}

Image<std::uint8_t> makeObjectMask(const Image<std::uint32_t>& objectIds,
                                   const std::vector<std::uint32_t>& ids, int dilation)
{
    requireNonNegative(dilation, "makeObjectMask", "dilation");
    const std::unordered_set<std::uint32_t> wanted(ids.begin(), ids.end());
    Image<std::uint8_t> mask(objectIds.width, objectIds.height, 0);
    for (std::size_t i = 0; i < mask.pixels.size(); ++i)
        mask.pixels[i] = wanted.count(objectIds.pixels[i]) ? 1 : 0;
    return dilateSquare(mask, dilation);
}

} // namespace rtlab::metrics
