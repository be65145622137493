#pragma once
// Texel formats that images can have, and half-float conversion for R16G16B16A16_SFLOAT data.

#include <cstddef>
#include <cstdint>
#include <string_view>

namespace rtlab::gpu {

//! Image texel formats. Each maps to the Vulkan format of the same name.
enum class Format {
    R32Float,    //!< VK_FORMAT_R32_SFLOAT, GLSL layout qualifier r32f
    RGBA32Float, //!< VK_FORMAT_R32G32B32A32_SFLOAT, rgba32f
    RGBA16Float, //!< VK_FORMAT_R16G16B16A16_SFLOAT, rgba16f (texels are 4 x uint16 halves)
    RGBA8Unorm,  //!< VK_FORMAT_R8G8B8A8_UNORM, rgba8
    R32Uint,     //!< VK_FORMAT_R32_UINT, r32ui
};

//! Bytes per texel (tightly packed, as upload/download expect).
std::size_t getTexelSize(Format format);

//! Number of channels (1 or 4).
int getChannelCount(Format format);

//! The Vulkan name, e.g. "R32G32B32A32_SFLOAT".
std::string_view getFormatName(Format format);

//! IEEE 754 binary16 from binary32, rounding to nearest even (overflow gives infinity; NaN stays
//! NaN).
std::uint16_t packHalf(float value);

//! binary32 from binary16 (exact).
float unpackHalf(std::uint16_t half);

} // namespace rtlab::gpu
