#pragma once
// An 8-bit RGB raster and its PNG file form (libpng).
#include <cstdint>
#include <fstream>
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

/// An animated PNG (APNG: PNG 3rd edition's acTL/fcTL/fdAT chunks), written frame by frame so
/// that a long movie is never held in memory: the frame count is fixed up front, every frame has
/// the writer's size, each is shown for 1/fps s and the animation loops. Viewers without APNG
/// support show the first frame. zlib compresses the rows (filter "none"). Throws
/// std::runtime_error naming the file on an I/O error, std::invalid_argument on a frame of
/// another size or a frame count that does not match.
class ApngWriter {
 public:
  ApngWriter(const std::string& path, int width, int height, int frames, int fps);
  void add(const Image& frame);
  void finish();  ///< checks that every announced frame was added and closes the file

 private:
  void chunk(const char type[4], const std::vector<std::uint8_t>& data);
  std::string path_;
  std::ofstream out_;
  int width_, height_, frames_, fps_, added_ = 0;
  std::uint32_t sequence_ = 0;
};

}  // namespace ibrod::render
