#include "gpu/bus_counters.h"

#include <atomic>

namespace rtlab::gpu {

namespace {
std::atomic<std::uint64_t> gUploadBytes{0}, gReadbackBytes{0}, gSubmits{0}, gWaits{0}, gWaitNs{0};
} // namespace

BusCounters getBusCounters()
{
    return {gUploadBytes.load(std::memory_order_relaxed), gReadbackBytes.load(std::memory_order_relaxed),
            gSubmits.load(std::memory_order_relaxed), gWaits.load(std::memory_order_relaxed),
            double(gWaitNs.load(std::memory_order_relaxed)) * 1e-6};
}

namespace detail {
void countUpload(std::size_t bytes)
{
    gUploadBytes.fetch_add(bytes, std::memory_order_relaxed);
}
void countReadback(std::size_t bytes)
{
    gReadbackBytes.fetch_add(bytes, std::memory_order_relaxed);
}
void countSubmit()
{
    gSubmits.fetch_add(1, std::memory_order_relaxed);
}
void countWait(double ms)
{
    gWaits.fetch_add(1, std::memory_order_relaxed);
    gWaitNs.fetch_add(std::uint64_t(ms * 1e6 + 0.5), std::memory_order_relaxed);
}
} // namespace detail

} // namespace rtlab::gpu
