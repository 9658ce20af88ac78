// PNG files through libpng's simplified API (png_image_*), which handles libpng's errors
// internally, so that no longjmp crosses C++ frames. Written through io/atomic_file.h like every
// other output file.
#include <png.h>

#include <string>

#include "focal/render/render.h"
#include "io/atomic_file.h"
#include "io/file_bytes.h"

namespace focal {

void write_png(const std::filesystem::path& path, const Image& image) {
  if (image.width < 1 || image.height < 1 ||
      image.rgb.size() != 3 * static_cast<std::size_t>(image.width) * image.height) {
    throw InvalidInput("write_png: the image has " + std::to_string(image.rgb.size()) +
                       " bytes for " + std::to_string(image.width) + " x " +
                       std::to_string(image.height) + " RGB pixels");
  }
  io_detail::AtomicFile file(path);
  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  png.width = static_cast<png_uint_32>(image.width);
  png.height = static_cast<png_uint_32>(image.height);
  png.format = PNG_FORMAT_RGB;
  const bool written =
      png_image_write_to_stdio(&png, file.file(), 0, image.rgb.data(), 0, nullptr) != 0;
  const std::string message = png.message;
  png_image_free(&png);
  if (!written) io_detail::fail(path, "cannot write PNG: " + message);
  file.commit();
}

Image read_png(const std::filesystem::path& path) {
  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&png, path.c_str())) {
    const std::string message = png.message;
    png_image_free(&png);
    io_detail::fail(path, "cannot read as PNG: " + message);
  }
  png.format = PNG_FORMAT_RGB;
  Image image;
  image.width = static_cast<int>(png.width);
  image.height = static_cast<int>(png.height);
  image.rgb.resize(PNG_IMAGE_SIZE(png));
  // Transparent pixels are composed onto white, the background of focal's pictures.
  const png_color white{255, 255, 255};
  if (!png_image_finish_read(&png, &white, image.rgb.data(), 0, nullptr)) {
    const std::string message = png.message;
    png_image_free(&png);
    io_detail::fail(path, "cannot decode PNG: " + message);
  }
  return image;
}

}  // namespace focal
