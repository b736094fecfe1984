#pragma once
// An 8-bit RGB raster and its PNG file form (libpng).
#include <cstdint>
#include <string>
#include <vector>

namespace ibrod::render {

struct Rgb {
  std::uint8_t r = 0, g = 0, b = 0;
  bool operator==(const Rgb&) const = default;
};

/// width × height pixels, row-major from the top-left corner.
struct Image {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgb;  ///< [height x width x 3]

  Image() = default;
  Image(int w, int h, Rgb fill = {});
  Rgb at(int x, int y) const {
    const std::uint8_t* p = &rgb[3 * (std::size_t(y) * std::size_t(width) + std::size_t(x))];
    return {p[0], p[1], p[2]};
  }
  void set(int x, int y, Rgb c) {
    std::uint8_t* p = &rgb[3 * (std::size_t(y) * std::size_t(width) + std::size_t(x))];
    p[0] = c.r, p[1] = c.g, p[2] = c.b;
  }
};

/// Writes an 8-bit RGB PNG. Throws std::runtime_error naming the file on failure.
void write_png(const std::string& path, const Image& image);

/// Reads any PNG as 8-bit RGB (palette, grey, 16-bit and alpha are converted; alpha is dropped).
/// Throws std::runtime_error naming the file on failure.
Image read_png(const std::string& path);

}  // namespace ibrod::render
