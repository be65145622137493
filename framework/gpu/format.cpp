#include "gpu/format.h"

#include <bit>
#include <cstring>

namespace rtlab::gpu {

std::size_t getTexelSize(Format format)
{
    switch (format) {
    case Format::R32Float:
        return 4;
    case Format::RGBA32Float:
        return 16;
    case Format::RGBA16Float:
        return 8;
    case Format::RGBA8Unorm:
        return 4;
    case Format::R32Uint:
        return 4;
    }
    return 0;
}

int getChannelCount(Format format)
{
    return format == Format::R32Float || format == Format::R32Uint ? 1 : 4;
}

std::string_view getFormatName(Format format)
{
    switch (format) {
    case Format::R32Float:
        return "R32_SFLOAT";
    case Format::RGBA32Float:
        return "R32G32B32A32_SFLOAT";
    case Format::RGBA16Float:
        return "R16G16B16A16_SFLOAT";
    case Format::RGBA8Unorm:
        return "R8G8B8A8_UNORM";
    case Format::R32Uint:
        return "R32_UINT";
    }
    return "?";
}

std::uint16_t packHalf(float value)
{
    const std::uint32_t bits = std::bit_cast<std::uint32_t>(value);
    const std::uint32_t sign = (bits >> 16) & 0x8000u;
    const std::uint32_t exponent = (bits >> 23) & 0xffu;
    std::uint32_t mantissa = bits & 0x7fffffu;

    if (exponent == 0xffu) // infinity or NaN (keep NaN quiet and non-zero)
        return static_cast<std::uint16_t>(sign | 0x7c00u | (mantissa != 0 ? 0x200u : 0u));

    const int unbiased = static_cast<int>(exponent) - 127;
    if (unbiased > 15) // too large even before rounding
        return static_cast<std::uint16_t>(sign | 0x7c00u);

    if (unbiased >= -14) {
        // Normal half: keep 10 mantissa bits, round the 13 dropped bits to nearest even.
        std::uint32_t half = (static_cast<std::uint32_t>(unbiased + 15) << 10) | (mantissa >> 13);
        const std::uint32_t dropped = mantissa & 0x1fffu;
        if (dropped > 0x1000u || (dropped == 0x1000u && (half & 1u)))
            ++half; // a carry into the exponent is correct, up to infinity
        return static_cast<std::uint16_t>(sign | half);
    }
    if (unbiased < -25) // below half the smallest subnormal: rounds to zero
        return static_cast<std::uint16_t>(sign);

    // Subnormal half: value = m * 2^-24 with m < 1024.
    mantissa |= 0x800000u;           // implicit leading one
    const int shift = -unbiased - 1; // 14..24: bits dropped from the 24-bit significand
    std::uint32_t half = mantissa >> shift;
    const std::uint32_t dropped = mantissa & ((1u << shift) - 1u);
    const std::uint32_t halfway = 1u << (shift - 1);
    if (dropped > halfway || (dropped == halfway && (half & 1u)))
        ++half;
    return static_cast<std::uint16_t>(sign | half);
}

float unpackHalf(std::uint16_t half)
{
    const std::uint32_t sign = static_cast<std::uint32_t>(half & 0x8000u) << 16;
    const std::uint32_t exponent = (half >> 10) & 0x1fu;
    std::uint32_t mantissa = half & 0x3ffu;
    std::uint32_t bits = 0;
    if (exponent == 0x1fu) {
        bits = sign | 0x7f800000u | (mantissa << 13);
    } else if (exponent != 0) {
        bits = sign | ((exponent + 112u) << 23) | (mantissa << 13);
    } else if (mantissa != 0) {
        // Subnormal: normalise.
        int e = -1;
        do {
            ++e;
            mantissa <<= 1;
        } while (!(mantissa & 0x400u));
        bits = sign | (static_cast<std::uint32_t>(112 - e) << 23) | ((mantissa & 0x3ffu) << 13);
    } else {
        bits = sign;
    }
    return std::bit_cast<float>(bits);
}

} // namespace rtlab::gpu
