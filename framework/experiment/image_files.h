#pragma once
// Per-run images for looking (PNG, 8-bit, tone-mapped by the report) and for numbers (EXR,
// float32, exactly the values the metrics saw).

#include "core/image.h"

#include <glm/vec3.hpp>

#include <string>

namespace rtlab::experiment {

//! Writes a one-channel float32 EXR. Throws rtlab::Error naming the path on failure.
void writeExr(const Image<float>& image, const std::string& path);
//! Writes an RGB float32 EXR.
void writeExr(const Image<glm::vec3>& image, const std::string& path);
//! Writes an 8-bit RGB PNG of display values in [0, 1] (already tonemapped and encoded).
void writePng(const Image<glm::vec3>& display, const std::string& path);
//! Reads the first three channels of an EXR.
Image<glm::vec3> readExrRgb(const std::string& path);
//! Reads the first 3 channels of a PNG (writePng's files) as display values in [0, 1].
Image<glm::vec3> readPngRgb(const std::string& path);
//! Reads a one-channel EXR (the first channel).
Image<float> readExrScalar(const std::string& path);

} // namespace rtlab::experiment
