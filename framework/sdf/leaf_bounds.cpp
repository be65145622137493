#include "sdf/leaf_bounds.h"

#include <algorithm>
#include <cmath>

namespace rtlab::sdf::detail {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

} // namespace

std::size_t evaluateLipschitzLeaf(const glm::ivec3& n, const std::vector<Op>& ops,
                                  const std::vector<glm::dvec3>& positions, const LeafBand& limits,
                                  const FaceSeeds* seeds, std::vector<double>& values,
                                  std::vector<double>& bound, std::vector<std::uint8_t>& known,
                                  std::uint64_t& primitiveEvaluations)
{
    const std::size_t count = values.size();
    const double band = limits.band;
    const double lipschitz = limits.lipschitz;
    const double step = limits.step * lipschitz;
    const std::vector<double>& reach = limits.reach;
    const std::size_t strides[3] = {1, std::size_t(n.x), std::size_t(n.x) * std::size_t(n.y)};
    const auto evaluate = [&](std::size_t i) {
        double v = kInf;
        for (const Op& op : ops) {
            if (isUnchangedBy(op, v, limits.margin))
                continue;
            v = applyOp(op.kind, v, op.edit->evaluatePrimitive(positions[i]), op.edit->blend);
            ++primitiveEvaluations;
        }
        return v;
    };
    bound.assign(count, -kInf); // |value| (evaluated) or a lower bound of it
    known.assign(count, 0);
    std::size_t evaluated = 0;
    // The culled siblings' bounds, one spacing in, on the face samples (values holds the
    // sign until the sample is decided).
    if (seeds != nullptr)
        for (int face = 0; face < 6; ++face) {
            const double b = seeds->bound[std::size_t(face)] - step;
            if (!(b > band))
                continue;
            const int axis = face / 2;
            const int layer = (face & 1) ? n[axis] - 1 : 0;
            const int u = (axis + 1) % 3, v = (axis + 2) % 3;
            for (int j = 0; j < n[v]; ++j)
                for (int k = 0; k < n[u]; ++k) {
                    glm::ivec3 at(0);
                    at[axis] = layer;
                    at[u] = k;
                    at[v] = j;
                    const std::size_t i = std::size_t(at.x) * strides[0] +
                                          std::size_t(at.y) * strides[1] +
                                          std::size_t(at.z) * strides[2];
                    if (b > bound[i]) {
                        bound[i] = b;
                        values[i] = seeds->sign[std::size_t(face)] * b;
                    }
                }
        }
    // The corners (fewer where the leaf is one sample thin along an axis).
    std::array<std::size_t, 8> corner{};
    std::array<glm::ivec3, 8> cornerAt{};
    int corners = 0;
    bool provenOutside = false; // a corner a sibling proved outside: only a lower bound there
    for (int k = 0; k < 8; ++k) {
        const glm::ivec3 at((k & 1) ? n.x - 1 : 0, (k & 2) ? n.y - 1 : 0, (k & 4) ? n.z - 1 : 0);
        const std::size_t i = std::size_t(at.x) * strides[0] + std::size_t(at.y) * strides[1] +
                              std::size_t(at.z) * strides[2];
        if (known[i])
            continue;
        known[i] = 1;
        bool proven = false; // by a tight seed on one of the corner's three faces
        if (seeds != nullptr && bound[i] > band)
            for (int axis = 0; axis < 3; ++axis) {
                const int face = 2 * axis + (((k >> axis) & 1) ? 1 : 0);
                proven = proven || (seeds->tight[std::size_t(face)] &&
                                    seeds->bound[std::size_t(face)] - step > band);
            }
        if (!proven) {
            values[i] = evaluate(i);
            bound[i] = std::abs(values[i]);
            known[i] = 2; // exact
            ++evaluated;
        }
        provenOutside = provenOutside || (proven && values[i] > 0.0);
        corner[std::size_t(corners)] = i;
        cornerAt[std::size_t(corners++)] = at;
    }
    // A convex field (one convex primitive) is at most the trilinear interpolation of any upper
    // bounds of its values at the leaf's corners: a sample's trilinear weights are a convex
    // combination of the corners that reproduces its position, so f(sample) <= sum w_k f(c_k)
    // (Jensen). An evaluated corner gives its value; a corner a sibling proved inside gives its
    // stored -bound >= f; one proved outside gives no upper bound, and then nothing is proven
    // this way. This proves the samples inside a face tilted against the grid, which the
    // Lipschitz balls and one-spacing chains leave to evaluation (csg_gallery's rotated cube).
    const bool convex = isSingleConvexPrimitive(ops);
    const bool useUpper = convex && !provenOutside;
    std::array<double, 8> upper{};
    for (int k = 0; k < 8; ++k)
        upper[std::size_t(k)] = values[std::size_t((k & 1) ? n.x - 1 : 0) * strides[0] +
                                       std::size_t((k & 2) ? n.y - 1 : 0) * strides[1] +
                                       std::size_t((k & 4) ? n.z - 1 : 0) * strides[2]];
    // The trilinear weights of each axis's samples (0 where the leaf is one sample thin).
    const auto weight = [&](int axis, int at) {
        return n[axis] > 1 ? double(at) / double(n[axis] - 1) : 0.0;
    };
    // Sweep each axis from the side whose corners are farther from the surface.
    int direction[3];
    for (int axis = 0; axis < 3; ++axis) {
        double low = 0.0, high = 0.0;
        for (int k = 0; k < corners; ++k) {
            const double b = bound[corner[std::size_t(k)]];
            (cornerAt[std::size_t(k)][axis] == 0 ? low : high) += b;
        }
        direction[axis] = high > low ? -1 : 1;
    }
    // Only corners farther than one spacing past the band can prove another sample.
    int useful = 0;
    for (int k = 0; k < corners; ++k)
        if (bound[corner[std::size_t(k)]] - step > band) {
            corner[std::size_t(useful)] = corner[std::size_t(k)];
            cornerAt[std::size_t(useful++)] = cornerAt[std::size_t(k)];
        }
    const auto index = [&](const glm::ivec3& at) {
        return std::size_t(at.x) * strides[0] + std::size_t(at.y) * strides[1] +
               std::size_t(at.z) * strides[2];
    };
    for (int zi = 0; zi < n.z; ++zi)
        for (int yi = 0; yi < n.y; ++yi)
            for (int xi = 0; xi < n.x; ++xi) {
                const glm::ivec3 at(direction[0] > 0 ? xi : n.x - 1 - xi,
                                    direction[1] > 0 ? yi : n.y - 1 - yi,
                                    direction[2] > 0 ? zi : n.z - 1 - zi);
                const std::size_t i = index(at);
                if (known[i])
                    continue;
                double lowest = bound[i]; // a sibling's seed, or -inf
                double sign = values[i] < 0.0 ? -1.0 : 1.0;
                for (int k = 0; k < useful; ++k) {
                    const glm::ivec3 d = at - cornerAt[std::size_t(k)];
                    const double b =
                        bound[corner[std::size_t(k)]] -
                        lipschitz * reach[std::size_t(d.x * d.x + d.y * d.y + d.z * d.z)];
                    if (b > lowest) {
                        lowest = b;
                        sign = values[corner[std::size_t(k)]] < 0.0 ? -1.0 : 1.0;
                    }
                }
                const int sweep[3] = {xi, yi, zi};
                for (int axis = 0; axis < 3; ++axis) {
                    if (sweep[axis] == 0)
                        continue;
                    glm::ivec3 back = at;
                    back[axis] -= direction[axis];
                    const std::size_t j = index(back);
                    const double b = bound[j] - step;
                    if (b > lowest) {
                        lowest = b;
                        sign = values[j] < 0.0 ? -1.0 : 1.0;
                    }
                }
                known[i] = 1;
                if (lowest > band) {
                    values[i] = sign * lowest;
                    bound[i] = lowest;
                    continue;
                }
                if (useUpper) {
                    const double tx = weight(0, at.x), ty = weight(1, at.y), tz = weight(2, at.z);
                    const auto lerp = [](double a, double b, double t) { return a + t * (b - a); };
                    const double y0 =
                        lerp(lerp(upper[0], upper[1], tx), lerp(upper[2], upper[3], tx), ty);
                    const double y1 =
                        lerp(lerp(upper[4], upper[5], tx), lerp(upper[6], upper[7], tx), ty);
                    const double above = lerp(y0, y1, tz); // f(sample) <= above
                    if (above < -(band + limits.margin)) {
                        values[i] = above;
                        bound[i] = -above;
                        continue;
                    }
                }
                if (convex) {
                    // Along a sweep axis, a convex field lies above the line through the two
                    // exact samples behind: f(i) >= 2 f(i - 1) - f(i - 2). Where a face is
                    // tilted this proves the samples outside it that a whole spacing's
                    // Lipschitz step leaves to evaluation.
                    double below = -kInf; // f(sample) >= below
                    for (int axis = 0; axis < 3; ++axis) {
                        if (sweep[axis] < 2)
                            continue;
                        glm::ivec3 back = at;
                        back[axis] -= direction[axis];
                        const std::size_t j1 = index(back);
                        back[axis] -= direction[axis];
                        const std::size_t j2 = index(back);
                        if (known[j1] == 2 && known[j2] == 2)
                            below = std::max(below, 2.0 * values[j1] - values[j2]);
                    }
                    if (below > band + limits.margin) {
                        values[i] = below;
                        bound[i] = below;
                        continue;
                    }
                }
                values[i] = evaluate(i);
                bound[i] = std::abs(values[i]);
                known[i] = 2;
                ++evaluated;
            }
    return evaluated;
}

} // namespace rtlab::sdf::detail
