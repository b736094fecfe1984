// PNG I/O through libpng's simplified API (png_image_*), which needs no setjmp error handling.
#include "render/image.hpp"

#include <png.h>
#include <zlib.h>

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

namespace {

void put32(std::vector<std::uint8_t>& v, std::uint32_t x) {
  for (int s = 24; s >= 0; s -= 8) v.push_back(std::uint8_t(x >> s));
}
void put16(std::vector<std::uint8_t>& v, std::uint16_t x) {
  v.push_back(std::uint8_t(x >> 8));
  v.push_back(std::uint8_t(x));
}

}  // namespace

ApngWriter::ApngWriter(const std::string& path, int width, int height, int frames, int fps)
    : path_(path),
      out_(path, std::ios::binary | std::ios::trunc),
      width_(width),
      height_(height),
      frames_(frames),
      fps_(fps) {
  if (width <= 0 || height <= 0 || frames <= 0 || fps <= 0 || fps > 65535)
    throw std::invalid_argument("ApngWriter: size " + std::to_string(width) + "x" +
                                std::to_string(height) + ", " + std::to_string(frames) +
                                " frames at " + std::to_string(fps) + "/s");
  if (!out_) throw std::runtime_error("cannot write APNG '" + path + "'");
  static const std::uint8_t signature[8] = {137, 80, 78, 71, 13, 10, 26, 10};
  out_.write(reinterpret_cast<const char*>(signature), 8);
  std::vector<std::uint8_t> ihdr;
  put32(ihdr, std::uint32_t(width));
  put32(ihdr, std::uint32_t(height));
  ihdr.insert(ihdr.end(), {8, 2, 0, 0, 0});  // 8-bit RGB, deflate, adaptive filters, no interlace
  chunk("IHDR", ihdr);
  std::vector<std::uint8_t> actl;
  put32(actl, std::uint32_t(frames));
  put32(actl, 0);  // loop for ever
  chunk("acTL", actl);
}

void ApngWriter::chunk(const char type[4], const std::vector<std::uint8_t>& data) {
  std::vector<std::uint8_t> head;
  put32(head, std::uint32_t(data.size()));
  head.insert(head.end(), type, type + 4);
  uLong crc = crc32(0, reinterpret_cast<const Bytef*>(type), 4);
  if (!data.empty()) crc = crc32(crc, data.data(), uInt(data.size()));
  std::vector<std::uint8_t> tail;
  put32(tail, std::uint32_t(crc));
  out_.write(reinterpret_cast<const char*>(head.data()), std::streamsize(head.size()));
  out_.write(reinterpret_cast<const char*>(data.data()), std::streamsize(data.size()));
  out_.write(reinterpret_cast<const char*>(tail.data()), std::streamsize(tail.size()));
  if (!out_) throw std::runtime_error("cannot write APNG '" + path_ + "'");
}

void ApngWriter::add(const Image& frame) {
  if (frame.width != width_ || frame.height != height_)
    throw std::invalid_argument("ApngWriter: a " + std::to_string(frame.width) + "x" +
                                std::to_string(frame.height) + " frame in a " +
                                std::to_string(width_) + "x" + std::to_string(height_) + " movie");
  if (added_ == frames_)
    throw std::invalid_argument("ApngWriter: more than the " + std::to_string(frames_) +
                                " frames announced");
  std::vector<std::uint8_t> fctl;
  put32(fctl, sequence_++);
  put32(fctl, std::uint32_t(width_));
  put32(fctl, std::uint32_t(height_));
  put32(fctl, 0);  // x offset
  put32(fctl, 0);  // y offset
  put16(fctl, 1);  // delay 1/fps s
  put16(fctl, std::uint16_t(fps_));
  fctl.push_back(0);  // dispose: none
  fctl.push_back(0);  // blend: source
  chunk("fcTL", fctl);
  // the rows, each after its filter byte (0: none), deflated
  const std::size_t row = 3 * std::size_t(width_);
  std::vector<std::uint8_t> raw((row + 1) * std::size_t(height_));
  for (int y = 0; y < height_; ++y) {
    raw[std::size_t(y) * (row + 1)] = 0;
    std::memcpy(&raw[std::size_t(y) * (row + 1) + 1], &frame.rgb[std::size_t(y) * row], row);
  }
  uLongf size = compressBound(uLong(raw.size()));
  std::vector<std::uint8_t> z(size);
  if (compress2(z.data(), &size, raw.data(), uLong(raw.size()), 6) != Z_OK)
    throw std::runtime_error("cannot compress a frame of APNG '" + path_ + "'");
  z.resize(size);
  if (added_ == 0) {
    chunk("IDAT", z);  // the first frame is the default image
  } else {
    std::vector<std::uint8_t> fdat;
    put32(fdat, sequence_++);
    fdat.insert(fdat.end(), z.begin(), z.end());
    chunk("fdAT", fdat);
  }
  ++added_;
}

void ApngWriter::finish() {
  if (added_ != frames_)
    throw std::invalid_argument("ApngWriter: " + std::to_string(added_) + " of the " +
                                std::to_string(frames_) + " frames announced were added");
  chunk("IEND", {});
  out_.close();
  if (!out_) throw std::runtime_error("cannot write APNG '" + path_ + "'");
}

}  // namespace ibrod::render
