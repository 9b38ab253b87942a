// PNG in and out through libpng's simplified API.
#include <png.h>

#include <cstring>
#include <stdexcept>
#include <string>

#include "fissure/viewer/offscreen_context.hpp"

namespace fissure::viewer {

void write_png(const RgbaImage& image, const std::string& path) {
  png_image png;
  std::memset(&png, 0, sizeof png);
  png.version = PNG_IMAGE_VERSION;
  png.width = static_cast<png_uint_32>(image.width);
  png.height = static_cast<png_uint_32>(image.height);
  // The frame is opaque: store RGB (a quarter smaller) by dropping alpha on a black background.
  png.format = PNG_FORMAT_RGB;
  std::vector<std::uint8_t> rgb(static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height) * 3);
  for (std::size_t i = 0, n = rgb.size() / 3; i < n; ++i) std::memcpy(&rgb[i * 3], &image.pixels[i * 4], 3);
  if (png_image_write_to_file(&png, path.c_str(), 0, rgb.data(), 0, nullptr) == 0) {
    throw std::runtime_error("cannot write PNG '" + path + "': " + png.message);
  }
}

RgbaImage read_png(const std::string& path) {
  png_image png;
  std::memset(&png, 0, sizeof png);
  png.version = PNG_IMAGE_VERSION;
  if (png_image_begin_read_from_file(&png, path.c_str()) == 0) throw std::runtime_error("cannot read PNG '" + path + "': " + png.message);
  png.format = PNG_FORMAT_RGBA;
  RgbaImage image;
  image.width = static_cast<int>(png.width);
  image.height = static_cast<int>(png.height);
  image.pixels.resize(PNG_IMAGE_SIZE(png));
  if (png_image_finish_read(&png, nullptr, image.pixels.data(), 0, nullptr) == 0) {
    throw std::runtime_error("cannot decode PNG '" + path + "': " + png.message);
  }
  return image;
}

}  // namespace fissure::viewer
