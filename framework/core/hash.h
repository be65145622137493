#pragma once
// Content hashing for caches (SPIR-V, ground truth) and config identity (resume of sweeps).
// Not cryptographic: two independent 64-bit FNV-1a streams give a 128-bit key, which makes an
// accidental collision between cache entries practically impossible.

#include <cstdint>
#include <string>
#include <string_view>
#include <type_traits>

namespace rtlab {

class Hasher {
public:
    Hasher& addBytes(const void* data, std::size_t size);
    Hasher& add(std::string_view text);  //!< length-prefixed, so ("ab","c") != ("a","bc")
    template <class T>
        requires std::is_trivially_copyable_v<T>
    Hasher& addValue(const T& value)
    {
        return addBytes(&value, sizeof(T));
    }

    //! 32 lowercase hex digits.
    std::string hexDigest() const;
    std::uint64_t digest64() const { return mA ^ (mB * 0x9e3779b97f4a7c15ull); }

private:
    std::uint64_t mA = 0xcbf29ce484222325ull;  // FNV-1a offset basis
    std::uint64_t mB = 0x84222325cbf29ce4ull;  // second stream, different basis
};

//! Convenience: hexDigest() of one string.
std::string hashHex(std::string_view text);

} // namespace rtlab
