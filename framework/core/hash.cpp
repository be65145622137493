#include "core/hash.h"

#include <cstdio>

namespace rtlab {

namespace {
constexpr std::uint64_t kFnvPrime = 0x100000001b3ull;
}

Hasher& Hasher::addBytes(const void* data, std::size_t size)
{
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < size; ++i) {
        mA = (mA ^ p[i]) * kFnvPrime;
        mB = (mB ^ static_cast<unsigned char>(p[i] + 0x5b)) * kFnvPrime;
    }
    return *this;
}

Hasher& Hasher::add(std::string_view text)
{
    const std::uint64_t n = text.size();
    addValue(n);
    return addBytes(text.data(), text.size());
}

std::string Hasher::hexDigest() const
{
    char buf[33];
    std::snprintf(buf, sizeof buf, "%016llx%016llx", static_cast<unsigned long long>(mA),
                  static_cast<unsigned long long>(mB));
    return buf;
}

std::string hashHex(std::string_view text)
{
    return Hasher().add(text).hexDigest();
}

} // namespace rtlab
