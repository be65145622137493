#pragma once
// Converting raw timestamp-query values to milliseconds.

#include <cstdint>
#include <optional>

namespace rtlab::gpu {

//! Milliseconds between two raw timestamps of a queue with `validBits` valid bits and a tick of
//! `periodNs` nanoseconds. Only the low `validBits` bits are compared, so a counter that wrapped
//! once between the two is handled. Empty when the queue has no timestamps (validBits == 0) or
//! the period is not positive.
std::optional<double> convertTicksToMs(std::uint64_t begin, std::uint64_t end,
                                       std::uint32_t validBits, double periodNs);

} // namespace rtlab::gpu
