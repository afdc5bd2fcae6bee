#include "skinmesh/core/error.hpp"
#include "skinmesh/render/render.hpp"

#include <png.h>

namespace skinmesh {
namespace {

void to_stream(png_structp png, png_bytep data, png_size_t length) {
  auto* out = static_cast<std::ostream*>(png_get_io_ptr(png));
  out->write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(length));
}

void flush_stream(png_structp png) { static_cast<std::ostream*>(png_get_io_ptr(png))->flush(); }

}  // namespace

void write_png(std::ostream& out, const Image& image) {
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (!png || !info) {
    png_destroy_write_struct(&png, &info);
    output_error("", "cannot start a PNG");
  }
  if (setjmp(png_jmpbuf(png))) {  // libpng's error path
    png_destroy_write_struct(&png, &info);
    output_error("", "writing the PNG failed");
  }
  png_set_write_fn(png, &out, to_stream, flush_stream);
  png_set_IHDR(png, info, static_cast<png_uint_32>(image.width), static_cast<png_uint_32>(image.height), 8,
               PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  for (int y = 0; y < image.height; ++y)
    png_write_row(png, const_cast<png_bytep>(image.rgb.data() + static_cast<size_t>(y) * 3 * static_cast<size_t>(image.width)));
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  if (!out) output_error("", "writing the PNG failed");
}

}  // namespace skinmesh
