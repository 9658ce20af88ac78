// PNG files through libpng's simplified API (png_image_*), which handles libpng's errors
// internally, so that no longjmp crosses C++ frames.
#include <png.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <string>
#include <system_error>

#include "focal/render/render.h"

namespace focal {
namespace {

[[noreturn]] void fail(const std::filesystem::path& path, const std::string& what) {
  throw IoError(path.string() + ": " + what);
}

/// A name beside `path` no other writer uses: same folder (so the rename is atomic), hidden,
/// process id and a counter.
std::filesystem::path temporary_path(const std::filesystem::path& path) {
  static std::atomic<unsigned> counter{0};
  // Appended piecewise: GCC 12 gives a false -Wrestrict warning on "." + std::string.
  std::string name(1, '.');
  name += path.filename().string();
  name += ".tmp-";
  name += std::to_string(getpid());
  name += '-';
  name += std::to_string(counter++);
  return path.parent_path() / name;
}

void write_png_file(const std::filesystem::path& file, const Image& image,
                    const std::filesystem::path& target) {
  std::FILE* out = std::fopen(file.c_str(), "wbx");
  if (out == nullptr)
    fail(target, std::string("cannot create a file in its folder: ") + std::strerror(errno));
  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  png.width = static_cast<png_uint_32>(image.width);
  png.height = static_cast<png_uint_32>(image.height);
  png.format = PNG_FORMAT_RGB;
  const bool written = png_image_write_to_stdio(&png, out, 0, image.rgb.data(), 0, nullptr) != 0;
  const std::string message = png.message;
  png_image_free(&png);
  const bool flushed = std::fflush(out) == 0 && fsync(fileno(out)) == 0;
  const bool closed = std::fclose(out) == 0;
  if (!written) fail(target, "cannot write PNG: " + message);
  if (!flushed || !closed) fail(target, "cannot write (disk full?)");
}

}  // namespace

void write_png(const std::filesystem::path& path, const Image& image) {
  if (image.width < 1 || image.height < 1 ||
      image.rgb.size() != 3 * static_cast<std::size_t>(image.width) * image.height) {
    throw InvalidInput("write_png: the image has " + std::to_string(image.rgb.size()) +
                       " bytes for " + std::to_string(image.width) + " x " +
                       std::to_string(image.height) + " RGB pixels");
  }
  const std::filesystem::path temporary = temporary_path(path);
  try {
    write_png_file(temporary, image, path);
    std::error_code error;
    std::filesystem::rename(temporary, path, error);
    if (error) fail(path, "cannot rename the finished file into place: " + error.message());
  } catch (...) {
    std::error_code ignored;
    std::filesystem::remove(temporary, ignored);
    throw;
  }
}

Image read_png(const std::filesystem::path& path) {
  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&png, path.c_str())) {
    const std::string message = png.message;
    png_image_free(&png);
    fail(path, "cannot read as PNG: " + message);
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
    fail(path, "cannot decode PNG: " + message);
  }
  return image;
}

}  // namespace focal
