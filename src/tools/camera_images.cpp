// CameraImage to PNG files with libpng's classic interface: 16-bit samples are written as they are (no
// gamma conversion, big-endian as PNG stores them).
#include "soft_body_sim/tools/camera_images.h"

#include <cmath>
#include <cstdio>
#include <memory>
#include <stdexcept>

#include <png.h>

namespace soft_body_sim
{
namespace
{
struct FileCloser
{
  void operator()(std::FILE* file) const { std::fclose(file); }
};
using File = std::unique_ptr<std::FILE, FileCloser>;

/// Writes rows of `channels` samples of `bits` (8 or 16) per pixel; samples are bytes or host-order words.
void writePng(const std::string& path, int width, int height, int channels, int bits, const void* samples)
{
  File file(std::fopen(path.c_str(), "wb"));
  if (!file)
    throw std::runtime_error("cannot write '" + path + "'");
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (!info)
  {
    png_destroy_write_struct(&png, nullptr);
    throw std::runtime_error("cannot write '" + path + "': libpng could not start");
  }
  if (setjmp(png_jmpbuf(png)))
  {
    png_destroy_write_struct(&png, &info);
    throw std::runtime_error("cannot write '" + path + "' (disk full?)");
  }
  png_init_io(png, file.get());
  png_set_IHDR(png, info, static_cast<png_uint_32>(width), static_cast<png_uint_32>(height), bits,
               channels == 3 ? PNG_COLOR_TYPE_RGB : PNG_COLOR_TYPE_GRAY, PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  if (bits == 16)
    png_set_swap(png);  // host (little-endian) words to PNG's big-endian
  const std::size_t row = static_cast<std::size_t>(width) * static_cast<std::size_t>(channels) * (bits / 8u);
  const auto* bytes = static_cast<const png_byte*>(samples);
  for (int v = 0; v < height; ++v)
    png_write_row(png, bytes + static_cast<std::size_t>(v) * row);
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  if (std::fflush(file.get()) != 0)
    throw std::runtime_error("cannot write '" + path + "' (disk full?)");
}
}  // namespace

void writeCameraImages(const std::string& directory, const std::string& camera, std::uint64_t frame,
                       const CameraImage& image)
{
  char number[32];
  std::snprintf(number, sizeof number, "%06llu", static_cast<unsigned long long>(frame));
  const auto path = [&](const char* kind) { return directory + "/" + camera + "_" + kind + "_" + number + ".png"; };
  writePng(path("color"), image.width, image.height, 3, 8, image.color.data());
  const std::vector<std::uint16_t> depth = depthMillimetres(image);
  writePng(path("depth"), image.width, image.height, 1, 16, depth.data());
  writePng(path("mask"), image.width, image.height, 1, 16, image.mask.data());
}

GreyImage16 readGreyPng16(const std::string& path)
{
  File file(std::fopen(path.c_str(), "rb"));
  if (!file)
    throw std::runtime_error("cannot read '" + path + "'");
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (!info)
  {
    png_destroy_read_struct(&png, nullptr, nullptr);
    throw std::runtime_error("cannot read '" + path + "': libpng could not start");
  }
  if (setjmp(png_jmpbuf(png)))
  {
    png_destroy_read_struct(&png, &info, nullptr);
    throw std::runtime_error("cannot read '" + path + "': not a PNG");
  }
  png_init_io(png, file.get());
  png_read_png(png, info, PNG_TRANSFORM_SWAP_ENDIAN, nullptr);
  GreyImage16 image;
  image.width = static_cast<int>(png_get_image_width(png, info));
  image.height = static_cast<int>(png_get_image_height(png, info));
  const bool grey16 = png_get_bit_depth(png, info) == 16 && png_get_color_type(png, info) == PNG_COLOR_TYPE_GRAY;
  if (grey16)
  {
    png_bytepp rows = png_get_rows(png, info);
    for (int v = 0; v < image.height; ++v)
    {
      const auto* words = reinterpret_cast<const std::uint16_t*>(rows[v]);
      image.samples.insert(image.samples.end(), words, words + image.width);
    }
  }
  png_destroy_read_struct(&png, &info, nullptr);
  if (!grey16)
    throw std::runtime_error("'" + path + "' is not a 16-bit grey PNG");
  return image;
}

}  // namespace soft_body_sim
