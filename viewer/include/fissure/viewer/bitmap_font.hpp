#pragma once
// A tiny built-in 5×7 bitmap font for the overlay (no font files, no texture): digits, upper-
// case letters (lower case is drawn as upper case) and the punctuation the overlay uses.
#include <array>
#include <cstdint>

namespace fissure::viewer {

inline constexpr int kGlyphWidthPx = 5;
inline constexpr int kGlyphHeightPx = 7;
/// Advance per character (glyph + 1 px spacing) and per line (glyph + 3 px).
inline constexpr int kGlyphAdvancePx = 6;
inline constexpr int kLineAdvancePx = 10;

/// Rows top to bottom; bit 4 is the leftmost column. Unknown characters give a filled box so a
/// missing glyph shows instead of silently vanishing.
[[nodiscard]] const std::array<std::uint8_t, kGlyphHeightPx>& glyph_rows(char c) noexcept;

}  // namespace fissure::viewer
