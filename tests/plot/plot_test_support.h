#pragma once
// Reading back what the plot writers produce: PNG pixels and the text of PDF pages.

#include "plot/color.h"

#include <cstdint>
#include <string>
#include <vector>

namespace rtlab::plot::test {

//! 8-bit RGB pixels of a PNG, row 0 at the top.
struct Pixels {
    int width = 0;
    int height = 0;
    std::vector<std::uint8_t> rgb;

    Color at(int x, int y) const;
    //! Number of pixels exactly equal to `c`.
    std::size_t count(Color c) const;
    //! Number of distinct colours.
    std::size_t countDistinct() const;
};

//! Reads a PNG with OpenImageIO (alpha, if any, dropped). Fails the test if it cannot.
Pixels readPng(const std::string& path);

//! The whole file.
std::string readBytes(const std::string& path);

//! The content streams of a PDF, inflated where they are Flate-compressed, concatenated.
std::string readPdfContent(const std::string& path);

//! The string operands of the text-showing operators (Tj, TJ, ', ") in PDF content, unescaped.
std::vector<std::string> extractPdfStrings(const std::string& content);

//! A fresh empty folder under the test temporary directory.
std::string makeTempDir(const std::string& name);

} // namespace rtlab::plot::test
