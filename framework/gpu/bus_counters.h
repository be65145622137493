#pragma once
// What crosses the bus between the host and the device, counted where it happens: every upload
// (staged, or a memcpy into mapped device memory) and read-back of a buffer, image or render
// target, every queue submission and every host wait on a fence, with the wait's wall time.
// Process-wide and thread-safe; a reader takes two snapshots and their difference
// (pipeline/frame_graph.cpp does so around every pass). Data that shaders read over the bus from
// host-visible memory (BufferDesc::hostVisible) is counted when the host writes it.

#include <cstddef>
#include <cstdint>

namespace rtlab::gpu {

struct BusCounters {
    std::uint64_t uploadBytes = 0;   //!< host to device
    std::uint64_t readbackBytes = 0; //!< device to host
    std::uint64_t submits = 0;       //!< vkQueueSubmit calls
    std::uint64_t waits = 0;         //!< host waits on a fence
    double waitMs = 0.0;             //!< wall time the host spent in those waits

    BusCounters operator-(const BusCounters& earlier) const
    {
        return {uploadBytes - earlier.uploadBytes, readbackBytes - earlier.readbackBytes,
                submits - earlier.submits, waits - earlier.waits, waitMs - earlier.waitMs};
    }
};

//! The totals since the process started.
BusCounters getBusCounters();

namespace detail {
void countUpload(std::size_t bytes);
void countReadback(std::size_t bytes);
void countSubmit();
void countWait(double ms);
} // namespace detail

} // namespace rtlab::gpu
