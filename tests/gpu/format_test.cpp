// Format properties and the half-float conversion helpers.

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>

#include "gpu/format.h"

namespace rtlab::gpu {
namespace {

TEST(Format, SizesChannelsAndNames)
{
    EXPECT_EQ(getTexelSize(Format::R32Float), 4u);
    EXPECT_EQ(getTexelSize(Format::RGBA32Float), 16u);
    EXPECT_EQ(getTexelSize(Format::RGBA16Float), 8u);
    EXPECT_EQ(getTexelSize(Format::RGBA8Unorm), 4u);
    EXPECT_EQ(getTexelSize(Format::R32Uint), 4u);
    EXPECT_EQ(getChannelCount(Format::R32Float), 1);
    EXPECT_EQ(getChannelCount(Format::RGBA8Unorm), 4);
    EXPECT_EQ(getFormatName(Format::RGBA16Float), "R16G16B16A16_SFLOAT");
    EXPECT_EQ(getFormatName(Format::R32Uint), "R32_UINT");
}

TEST(Half, KnownValues)
{
    EXPECT_EQ(packHalf(0.0f), 0x0000);
    EXPECT_EQ(packHalf(-0.0f), 0x8000);
    EXPECT_EQ(packHalf(1.0f), 0x3c00);
    EXPECT_EQ(packHalf(-2.0f), 0xc000);
    EXPECT_EQ(packHalf(0.5f), 0x3800);
    EXPECT_EQ(packHalf(65504.0f), 0x7bff);              // largest finite half
    EXPECT_EQ(packHalf(1.0f / 3.0f), 0x3555);           // rounded to nearest
    EXPECT_EQ(packHalf(std::ldexp(1.0f, -14)), 0x0400); // smallest normal
    EXPECT_EQ(packHalf(std::ldexp(1.0f, -24)), 0x0001); // smallest subnormal
    EXPECT_EQ(packHalf(std::ldexp(1.0f, -25)), 0x0000); // tie to even: zero
    EXPECT_EQ(packHalf(std::ldexp(1.5f, -25)), 0x0001); // above the tie: rounds up
    EXPECT_EQ(packHalf(std::numeric_limits<float>::infinity()), 0x7c00);
    EXPECT_EQ(packHalf(-std::numeric_limits<float>::infinity()), 0xfc00);
    EXPECT_EQ(packHalf(1e6f), 0x7c00);                             // overflow
    EXPECT_EQ(packHalf(65520.0f), 0x7c00);                         // rounds up into infinity
    EXPECT_EQ(packHalf(1.0f + std::ldexp(1.0f, -11)), 0x3c00);     // tie: stays even
    EXPECT_EQ(packHalf(1.0f + 3 * std::ldexp(1.0f, -11)), 0x3c02); // tie: rounds to even
    const std::uint16_t nan = packHalf(std::numeric_limits<float>::quiet_NaN());
    EXPECT_EQ(nan & 0x7c00, 0x7c00);
    EXPECT_NE(nan & 0x03ff, 0);

    EXPECT_EQ(unpackHalf(0x3c00), 1.0f);
    EXPECT_EQ(unpackHalf(0xc000), -2.0f);
    EXPECT_EQ(unpackHalf(0x7bff), 65504.0f);
    EXPECT_EQ(unpackHalf(0x0001), std::ldexp(1.0f, -24));
    EXPECT_EQ(unpackHalf(0x03ff), std::ldexp(1023.0f, -24));
    EXPECT_EQ(unpackHalf(0x7c00), std::numeric_limits<float>::infinity());
    EXPECT_TRUE(std::isnan(unpackHalf(0x7e00)));
    EXPECT_TRUE(std::signbit(unpackHalf(0x8000)));
}

TEST(Half, EveryHalfRoundTripsThroughFloat)
{
    for (std::uint32_t bits = 0; bits <= 0xffff; ++bits) {
        const auto half = static_cast<std::uint16_t>(bits);
        const float f = unpackHalf(half);
        if (std::isnan(f))
            continue;
        ASSERT_EQ(packHalf(f), half) << std::hex << bits;
    }
}

TEST(Half, PackingRoundsToTheNearestHalf)
{
    // Between consecutive halves a and b, values below the midpoint go to a, above to b.
    for (std::uint32_t bits = 0; bits < 0x7bff; bits += 37) {
        const float a = unpackHalf(static_cast<std::uint16_t>(bits));
        const float b = unpackHalf(static_cast<std::uint16_t>(bits + 1));
        const float mid = 0.5f * (a + b); // exact: a and b have few significant bits
        ASSERT_EQ(packHalf(std::nextafter(mid, a)), bits);
        ASSERT_EQ(packHalf(std::nextafter(mid, b)), bits + 1);
    }
}

} // namespace
} // namespace rtlab::gpu
