#include "core/sampled_field.h"

#include <algorithm>

namespace rtlab {

const HermiteEdge* HermiteData::find(const glm::ivec3& s, int axis) const
{
    const std::uint64_t wanted = key(s, axis);
    const auto it = std::lower_bound(
        edges.begin(), edges.end(), wanted,
        [&](const HermiteEdge& e, std::uint64_t k) { return key(e.sample, e.axis) < k; });
    if (it == edges.end() || key(it->sample, it->axis) != wanted)
        return nullptr;
    return &*it;
}

void HermiteData::sort()
{
    std::sort(edges.begin(), edges.end(), [&](const HermiteEdge& a, const HermiteEdge& b) {
        return key(a.sample, a.axis) < key(b.sample, b.axis);
    });
}

} // namespace rtlab
