#pragma once
// Internal: sizes (pixels) and fonts (points at 72 dpi, i.e. pixels) of image grids.

#include "plot/color.h"

#include <array>
#include <string>

namespace rtlab::plot::detail {

inline constexpr int kMargin = 16;
inline constexpr int kGap = 8; //!< image to crops, crop to crop
inline constexpr int kColumnGap = 16;
inline constexpr int kRowGap = 20;
inline constexpr int kTitleHeight = 36;
inline constexpr int kColumnTitleHeight = 28;
inline constexpr int kRowTitleWidth = 30; //!< row titles are drawn rotated
inline constexpr int kColorBarGap = 24;
inline constexpr int kColorBarWidth = 20;
inline constexpr int kTickLabelWidth = 64;

inline constexpr float kTextScaleWidth = 320.0f; //!< image width (pixels) of text scale 1
inline constexpr float kMaxTextScale = 3.0f;
//! Fonts (and the text bands above) are multiplied by ImageGridLayout::textScale.
inline constexpr float kTitleFont = 18.0f;
inline constexpr float kHeadingFont = 15.0f;
inline constexpr float kTickFont = 12.0f;
inline constexpr float kColorBarLabelFont = 13.0f;
inline constexpr float kAverageGlyphWidth = 0.6f; //!< of the font size, for Arial-like fonts

//! Outline colours of crops 0, 1, ... (repeating): bright so that they show on renders.
inline constexpr std::array<Color, 5> kCropColors = {Color{255, 208, 0}, Color{0, 229, 255},
                                                     Color{255, 61, 245}, Color{106, 255, 0},
                                                     Color{255, 127, 0}};

//! A generous width estimate of `text` in pixels.
int estimateTextWidth(const std::string& text, float fontSize);

} // namespace rtlab::plot::detail
