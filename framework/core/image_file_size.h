#pragma once
// Checks of image files before rtlab allocates for their pixels or hands them to a decoder: a
// header that claims more pixels than rtlab reads, or more chunks than the file can hold, is a
// clear error instead of a giant allocation.

#include <string>

namespace rtlab {

//! Most values an image file may hold for rtlab to read it by default: 2^26 (an 8192 x 8192
//! image of one channel; a reference of 3840 x 2160 pixels with 7 channels holds 58 million).
inline constexpr long long kMaxImageFileValues = 1ll << 26;

//! The limit checkImageFileSize applies (kMaxImageFileValues unless set; the fuzz targets lower
//! it so that each input stays fast under the sanitizers).
long long getImageFileValueLimit();
void setImageFileValueLimit(long long values);

//! Throws rtlab::Error naming `path` unless the size is positive and at most
//! getImageFileValueLimit() values.
void checkImageFileSize(const std::string& path, long long width, long long height, long long channels);

//! Reads the header of the OpenEXR file at `path` (the layout of openexr.com's "OpenEXR File
//! Layout": magic number, version, attributes up to an empty name, then the chunk offset table)
//! and throws rtlab::Error naming the file unless it is a single-part, non-deep image whose data
//! window and channel list give a size checkImageFileSize accepts and whose file is long enough for
//! the offset table its size and compression imply (8 bytes per chunk).
void checkExrHeader(const std::string& path);

} // namespace rtlab
