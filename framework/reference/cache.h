#pragma once
// On-disk cache of reference results (internal to rtlab_reference): one folder per key under the
// cache root holding what writeReferenceExr writes. Entries are written to a temporary folder and
// renamed into place, so a concurrent reader never sees half an entry.

#include "reference/reference.h"

#include <optional>
#include <string>

namespace rtlab::reference {

//! The entry folder of `key` under `root`.
std::string getCacheEntryPath(const std::string& root, const std::string& key);
//! The stored result, or nullopt when there is none or it cannot be read or does not match.
std::optional<ReferenceResult> loadCachedReference(const std::string& root, const std::string& key,
                                                   Quantity quantity, int width, int height);
//! Stores `result` as the entry of `key`; returns the entry folder. Throws rtlab::Error.
std::string storeCachedReference(const std::string& root, const std::string& key,
                                 const ReferenceResult& result);

} // namespace rtlab::reference
