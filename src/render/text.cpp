// The 5×7 label font (text.hpp).
#include "render/text.hpp"

#include <array>
#include <cstdint>
#include <string_view>

namespace ibrod::render {

namespace {

struct Glyph {
  char32_t code;
  std::array<std::string_view, kGlyphH> rows;  ///< '#': ink
};

// The characters the labels use (time, writhe, ΔLk, Cs, the scale bar), and a few more.
constexpr Glyph kFont[] = {
    {U'0', {" ### ", "#   #", "#  ##", "# # #", "##  #", "#   #", " ### "}},
    {U'1', {"  #  ", " ##  ", "  #  ", "  #  ", "  #  ", "  #  ", " ### "}},
    {U'2', {" ### ", "#   #", "    #", "   # ", "  #  ", " #   ", "#####"}},
    {U'3', {"#### ", "    #", "    #", " ### ", "    #", "    #", "#### "}},
    {U'4', {"   # ", "  ## ", " # # ", "#  # ", "#####", "   # ", "   # "}},
    {U'5', {"#####", "#    ", "#### ", "    #", "    #", "#   #", " ### "}},
    {U'6', {" ### ", "#    ", "#    ", "#### ", "#   #", "#   #", " ### "}},
    {U'7', {"#####", "    #", "   # ", "  #  ", " #   ", " #   ", " #   "}},
    {U'8', {" ### ", "#   #", "#   #", " ### ", "#   #", "#   #", " ### "}},
    {U'9', {" ### ", "#   #", "#   #", " ####", "    #", "    #", " ### "}},
    {U'.', {"     ", "     ", "     ", "     ", "     ", " ##  ", " ##  "}},
    {U',', {"     ", "     ", "     ", "     ", " ##  ", "  #  ", " #   "}},
    {U'-', {"     ", "     ", "     ", "#####", "     ", "     ", "     "}},
    {U'+', {"     ", "  #  ", "  #  ", "#####", "  #  ", "  #  ", "     "}},
    {U'=', {"     ", "     ", "#####", "     ", "#####", "     ", "     "}},
    {U'(', {"   # ", "  #  ", " #   ", " #   ", " #   ", "  #  ", "   # "}},
    {U')', {" #   ", "  #  ", "   # ", "   # ", "   # ", "  #  ", " #   "}},
    {U'/', {"    #", "    #", "   # ", "  #  ", " #   ", "#    ", "#    "}},
    {U' ', {"     ", "     ", "     ", "     ", "     ", "     ", "     "}},
    {U'A', {" ### ", "#   #", "#   #", "#####", "#   #", "#   #", "#   #"}},
    {U'C', {" ####", "#    ", "#    ", "#    ", "#    ", "#    ", " ####"}},
    {U'K', {"#   #", "#  # ", "# #  ", "##   ", "# #  ", "#  # ", "#   #"}},
    {U'L', {"#    ", "#    ", "#    ", "#    ", "#    ", "#    ", "#####"}},
    {U'M', {"#   #", "## ##", "# # #", "# # #", "#   #", "#   #", "#   #"}},
    {U'T', {"#####", "  #  ", "  #  ", "  #  ", "  #  ", "  #  ", "  #  "}},
    {U'W', {"#   #", "#   #", "#   #", "# # #", "# # #", "## ##", "#   #"}},
    {U'd', {"    #", "    #", " ####", "#   #", "#   #", "#   #", " ####"}},
    {U'o', {"     ", "     ", " ### ", "#   #", "#   #", "#   #", " ### "}},
    {U'e', {"     ", "     ", " ### ", "#   #", "#####", "#    ", " ### "}},
    {U'k', {"#    ", "#    ", "#  # ", "# #  ", "##   ", "# #  ", "#  # "}},
    {U'n', {"     ", "     ", "# ## ", "##  #", "#   #", "#   #", "#   #"}},
    {U'r', {"     ", "     ", "# ## ", "##  #", "#    ", "#    ", "#    "}},
    {U's', {"     ", "     ", " ####", "#    ", " ### ", "    #", "#### "}},
    {U't', {" #   ", " #   ", "#### ", " #   ", " #   ", " #  #", "  ## "}},
    {U'u', {"     ", "     ", "#   #", "#   #", "#   #", "#  ##", " ## #"}},
    {U'w', {"     ", "     ", "#   #", "#   #", "# # #", "# # #", " # # "}},
    {U'x', {"     ", "     ", "#   #", " # # ", "  #  ", " # # ", "#   #"}},
    {U'y', {"     ", "     ", "#   #", "#   #", " ####", "    #", " ### "}},
    {U'z', {"     ", "     ", "#####", "   # ", "  #  ", " #   ", "#####"}},
    {U'µ', {"     ", "     ", "#   #", "#   #", "#   #", "#### ", "#    "}},
    {U'Δ', {"     ", "  #  ", "  #  ", " # # ", " # # ", "#   #", "#####"}},
    {U'Å', {"  #  ", " # # ", "  #  ", " ### ", "#   #", "#####", "#   #"}},
    {U'°', {" ##  ", "#  # ", " ##  ", "     ", "     ", "     ", "     "}},
};

constexpr Glyph kUnknown = {0, {"#####", "#   #", "#   #", "#   #", "#   #", "#   #", "#####"}};

const Glyph& glyph(char32_t c) {
  for (const Glyph& g : kFont)
    if (g.code == c) return g;
  return kUnknown;
}

// UTF-8 to code points (an invalid byte becomes U+FFFD, drawn as the box).
std::u32string decode(const std::string& s) {
  std::u32string out;
  for (std::size_t i = 0; i < s.size();) {
    const auto b = static_cast<unsigned char>(s[i]);
    int len = b < 0x80 ? 1 : (b >> 5) == 6 ? 2 : (b >> 4) == 14 ? 3 : (b >> 3) == 30 ? 4 : 0;
    if (len == 0 || i + std::size_t(len) > s.size()) {
      out += U'\uFFFD';
      ++i;
      continue;
    }
    char32_t c = len == 1 ? b : b & (0x7f >> len);
    for (int k = 1; k < len; ++k) c = (c << 6) | (static_cast<unsigned char>(s[i + k]) & 0x3f);
    out += c;
    i += std::size_t(len);
  }
  return out;
}

}  // namespace

int text_width(const std::string& utf8, int scale) {
  const auto n = int(decode(utf8).size());
  return n == 0 ? 0 : (n * kGlyphAdvance - 1) * scale;
}

void draw_text(Image& img, int x, int y, const std::string& utf8, int scale, Rgb colour) {
  int pen = x;
  for (char32_t c : decode(utf8)) {
    const Glyph& g = glyph(c);
    for (int r = 0; r < kGlyphH; ++r)
      for (int col = 0; col < kGlyphW; ++col) {
        if (g.rows[std::size_t(r)][std::size_t(col)] != '#') continue;
        for (int dy = 0; dy < scale; ++dy)
          for (int dx = 0; dx < scale; ++dx) {
            const int px = pen + col * scale + dx, py = y + r * scale + dy;
            if (px >= 0 && py >= 0 && px < img.width && py < img.height) img.set(px, py, colour);
          }
      }
    pen += kGlyphAdvance * scale;
  }
}

}  // namespace ibrod::render
