#include "reference/sequences.h"

namespace rtlab::reference {

std::uint32_t reverseBits32(std::uint32_t x)
{
    // The bits within each byte, then the bytes (one bswap).
    x = ((x >> 1) & 0x55555555u) | ((x & 0x55555555u) << 1);
    x = ((x >> 2) & 0x33333333u) | ((x & 0x33333333u) << 2);
    x = ((x >> 4) & 0x0f0f0f0fu) | ((x & 0x0f0f0f0fu) << 4);
    return __builtin_bswap32(x);
}

namespace {

// Dimension 1: primitive polynomial x + 1, m_k = 1, 3, 5, 15, 17, 51, ... [Sobol 1967];
// v_{k+1} = v_k ^ (v_k >> 1) generates the Pascal matrix mod 2. The product with the index is
// tabulated per index byte: the XOR of the direction numbers of every subset of 8 bits.
struct SobolTables {
    std::uint32_t byteColumns[4][256];
    constexpr SobolTables() : byteColumns{}, reversedByteColumns{}
    {
        std::uint32_t v[32] = {};
        v[0] = 1u << 31;
        for (int k = 1; k < 32; ++k)
            v[k] = v[k - 1] ^ (v[k - 1] >> 1);
        for (int b = 0; b < 4; ++b)
            for (int x = 0; x < 256; ++x) {
                std::uint32_t r = 0;
                for (int bit = 0; bit < 8; ++bit)
                    if (x & (1 << bit))
                        r ^= v[8 * b + bit];
                byteColumns[b][x] = r;
                std::uint32_t reversed = 0; // the same columns with their bits reversed
                for (int bit = 0; bit < 32; ++bit)
                    if (r & (1u << bit))
                        reversed |= 1u << (31 - bit);
                reversedByteColumns[b][x] = reversed;
            }
    }
    std::uint32_t reversedByteColumns[4][256];
};
constexpr SobolTables kSobolTables;

// reverseBits32(computeSobol32(index, 1)), from the reversed columns.
std::uint32_t computeReversedSobol32Dimension1(std::uint32_t index)
{
    return kSobolTables.reversedByteColumns[0][index & 0xffu] ^
           kSobolTables.reversedByteColumns[1][(index >> 8) & 0xffu] ^
           kSobolTables.reversedByteColumns[2][(index >> 16) & 0xffu] ^
           kSobolTables.reversedByteColumns[3][index >> 24];
}

} // namespace

std::uint32_t computeSobol32(std::uint32_t index, int dimension)
{
    if (dimension == 0)
        return reverseBits32(index); // generator matrix = identity: van der Corput
    return kSobolTables.byteColumns[0][index & 0xffu] ^
           kSobolTables.byteColumns[1][(index >> 8) & 0xffu] ^
           kSobolTables.byteColumns[2][(index >> 16) & 0xffu] ^
           kSobolTables.byteColumns[3][index >> 24];
}

namespace {

// Each step only lets bits influence bits above them (x * even constant, + seed, * odd), so the
// map is a bijection in which bit k depends on bits <= k only [Laine & Karras 2011]; constants
// and the seed-dependent multiply from [Burley 2020].
std::uint32_t permuteLaineKarras(std::uint32_t x, std::uint32_t seed)
{
    x ^= x * 0x3d20adeau;
    x += seed;
    x *= (seed >> 16) | 1u;
    x ^= x * 0x05526c56u;
    x ^= x * 0x53a22864u;
    return x;
}

} // namespace

std::uint32_t scrambleNestedUniform(std::uint32_t x, std::uint32_t seed)
{
    // Reversed, bit k depends on the more significant digits only: Owen's nested scrambling.
    return reverseBits32(permuteLaineKarras(reverseBits32(x), seed));
}

std::uint64_t mixBits64(std::uint64_t x)
{
    x ^= x >> 33;
    x *= 0xff51afd7ed558ccdull;
    x ^= x >> 33;
    x *= 0xc4ceb9fe1a85ec53ull;
    x ^= x >> 33;
    return x;
}

double toUnitInterval(std::uint32_t x)
{
    return (double(x) + 0.5) * (1.0 / 4294967296.0);
}

namespace {

//! sampleScrambledSobol2D with the stream's two hashes computed once by the caller.
glm::dvec2 sampleScrambledSobol2DHashed(std::uint32_t index, std::uint64_t h0, std::uint64_t h1)
{
    // Shuffle: nested uniform scrambling of the index maps every aligned block of 2^m indices
    // onto an aligned block of 2^m indices, so prefixes of 2^m samples stay (0,m,2)-nets.
    const std::uint32_t shuffled = scrambleNestedUniform(index, std::uint32_t(h0));
    // scrambleNestedUniform(v) = reverse(permute(reverse(v))); dimension 0 is reverse(shuffled)
    // and dimension 1's reversal comes from reversed tables, so two reversals cancel in each.
    const std::uint32_t x = reverseBits32(permuteLaineKarras(shuffled, std::uint32_t(h0 >> 32)));
    const std::uint32_t y =
        reverseBits32(permuteLaineKarras(computeReversedSobol32Dimension1(shuffled), std::uint32_t(h1)));
    return {toUnitInterval(x), toUnitInterval(y)};
}

//! The two hashes of a stream seed that sampleScrambledSobol2DHashed takes.
SobolStream hashStreamSeed(std::uint64_t streamSeed)
{
    SobolStream stream;
    stream.h0 = mixBits64(streamSeed);
    stream.h1 = mixBits64(stream.h0 ^ 0x9e3779b97f4a7c15ull);
    return stream;
}

} // namespace

glm::dvec2 sampleScrambledSobol2D(std::uint32_t index, std::uint64_t streamSeed)
{
    const SobolStream stream = hashStreamSeed(streamSeed);
    return sampleScrambledSobol2DHashed(index, stream.h0, stream.h1);
}

PixelSequence::PixelSequence(std::uint64_t seed, std::uint64_t pixelIndex)
    : mPixelSeed(mixBits64(mixBits64(seed ^ 0x243f6a8885a308d3ull) + pixelIndex))
{
}

SobolStream PixelSequence::getStream(std::uint32_t dimensionPair) const
{
    return hashStreamSeed(mPixelSeed ^ mixBits64(std::uint64_t(dimensionPair) + 1));
}

glm::dvec2 PixelSequence::get2D(const SobolStream& stream, std::uint32_t sampleIndex)
{
    return sampleScrambledSobol2DHashed(sampleIndex, stream.h0, stream.h1);
}

glm::dvec2 PixelSequence::get2D(std::uint32_t sampleIndex, std::uint32_t dimensionPair) const
{
    return get2D(getStream(dimensionPair), sampleIndex);
}

void PixelSequence::get2D(std::uint32_t first, std::uint32_t count, std::uint32_t dimensionPair,
                          glm::dvec2* out) const
{
    const SobolStream stream = getStream(dimensionPair);
    for (std::uint32_t i = 0; i < count; ++i)
        out[i] = sampleScrambledSobol2DHashed(first + i, stream.h0, stream.h1);
}

} // namespace rtlab::reference
