#include "gpu/timestamps.h"

namespace rtlab::gpu {

std::optional<double> convertTicksToMs(std::uint64_t begin, std::uint64_t end,
                                       std::uint32_t validBits, double periodNs)
{
    if (validBits == 0 || !(periodNs > 0.0))
        return std::nullopt;
    const std::uint64_t mask = validBits >= 64 ? ~0ull : ((1ull << validBits) - 1);
    const std::uint64_t ticks = ((end & mask) - (begin & mask)) & mask;
    return static_cast<double>(ticks) * periodNs * 1e-6;
}

} // namespace rtlab::gpu
