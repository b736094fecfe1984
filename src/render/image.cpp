// PNG I/O through libpng's simplified API (png_image_*), which needs no setjmp error handling.
#include "render/image.hpp"

#include <png.h>

#include <cstring>
#include <stdexcept>

namespace ibrod::render {

Image::Image(int w, int h, Rgb fill) : width(w), height(h) {
  if (w <= 0 || h <= 0)
    throw std::invalid_argument("Image: size " + std::to_string(w) + "x" + std::to_string(h) +
                                " is not positive");
  rgb.resize(3 * std::size_t(w) * std::size_t(h));
  for (std::size_t i = 0; i < rgb.size(); i += 3)
    rgb[i] = fill.r, rgb[i + 1] = fill.g, rgb[i + 2] = fill.b;
}

void write_png(const std::string& path, const Image& image) {
  png_image png;
  std::memset(&png, 0, sizeof png);
  png.version = PNG_IMAGE_VERSION;
  png.width = png_uint_32(image.width);
  png.height = png_uint_32(image.height);
  png.format = PNG_FORMAT_RGB;
  if (!png_image_write_to_file(&png, path.c_str(), 0, image.rgb.data(), 0, nullptr)) {
    const std::string why = png.message;
    png_image_free(&png);
    throw std::runtime_error("cannot write PNG '" + path + "': " + why);
  }
}

Image read_png(const std::string& path) {
  png_image png;
  std::memset(&png, 0, sizeof png);
  png.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&png, path.c_str()))
    throw std::runtime_error("cannot read PNG '" + path + "': " + png.message);
  png.format = PNG_FORMAT_RGB;
  Image image;
  image.width = int(png.width);
  image.height = int(png.height);
  image.rgb.resize(PNG_IMAGE_SIZE(png));
  const png_color white{255, 255, 255};  // under transparent pixels
  if (!png_image_finish_read(&png, &white, image.rgb.data(), 0, nullptr)) {
    const std::string why = png.message;
    png_image_free(&png);
    throw std::runtime_error("cannot read PNG '" + path + "': " + why);
  }
  return image;
}

}  // namespace ibrod::render
