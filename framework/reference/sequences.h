#pragma once
// Low-discrepancy samples for the ground truth: the first two dimensions of the Sobol sequence
// (a (0,2)-sequence in base 2), Owen-scrambled with a hash [Owen 1997; Laine & Karras 2011;
// Burley 2020] and padded: every 2D pair of dimensions has its own scramble and its own shuffle
// of the sample index, seeded by a hash of (seed, pixel, pair). Every prefix of 2^m samples of a
// pair is a (0,m,2)-net; pairs are decorrelated by the independent shuffles [Burley 2020].

#include <glm/vec2.hpp>

#include <cstdint>

namespace rtlab::reference {

//! Bits in reverse order (bit 0 <-> bit 31).
std::uint32_t reverseBits32(std::uint32_t x);
//! Dimension 0 (van der Corput) or 1 of the Sobol sequence as a 32-bit fraction [Sobol 1967].
std::uint32_t computeSobol32(std::uint32_t index, int dimension);
//! Nested uniform (Owen) scrambling of a 32-bit fraction: bit k is flipped by a hash of the bits
//! above it and the seed [Burley 2020, with the Laine-Karras style permutation].
std::uint32_t scrambleNestedUniform(std::uint32_t x, std::uint32_t seed);
//! A 64-bit finaliser with good avalanche (MurmurHash3 fmix64).
std::uint64_t mixBits64(std::uint64_t x);
//! Maps a 32-bit fraction to the open interval (0, 1).
double toUnitInterval(std::uint32_t x);

//! The shuffled, scrambled 2D Sobol point `index` for one stream seed.
glm::dvec2 sampleScrambledSobol2D(std::uint32_t index, std::uint64_t streamSeed);

//! The two hashes that seed one dimension pair of one pixel's sequence.
struct SobolStream {
    std::uint64_t h0 = 0;
    std::uint64_t h1 = 0;
};

//! The samples of one pixel: pair `dimensionPair` of sample `sampleIndex`.
class PixelSequence {
public:
    PixelSequence(std::uint64_t seed, std::uint64_t pixelIndex);
    glm::dvec2 get2D(std::uint32_t sampleIndex, std::uint32_t dimensionPair) const;
    //! The hashes of pair `dimensionPair`, for a caller that draws many samples of it.
    SobolStream getStream(std::uint32_t dimensionPair) const;
    //! Sample `sampleIndex` of a stream: get2D(sampleIndex, pair) with stream = getStream(pair).
    static glm::dvec2 get2D(const SobolStream& stream, std::uint32_t sampleIndex);
    //! Samples first .. first + count - 1 of one dimension pair into out[0 .. count - 1].
    void get2D(std::uint32_t first, std::uint32_t count, std::uint32_t dimensionPair, glm::dvec2* out) const;

private:
    std::uint64_t mPixelSeed;
};

} // namespace rtlab::reference
