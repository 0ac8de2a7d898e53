// PNG / JPEG reading and PNG writing with libpng and libjpeg (image_io.hpp).
//
// Both libraries report errors by longjmp. Everything that has to be cleaned up after one (the
// library handles, the output Mat, the message) lives in an object of the caller; the functions
// that call setjmp create no C++ objects with destructors, so a longjmp skips none.
#include "io/formats/image_io.hpp"

#include <png.h>
#include <zlib.h>

#include <cerrno>
#include <cmath>
#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <utility>

// After <cstdio>: jpeglib.h needs FILE and size_t.
#include <jpeglib.h>

namespace proxseg::detail {
namespace {

constexpr std::size_t kMessageSize = 256;

// Not inlined into the functions that call setjmp (gcc's -Wclobbered on its loop variable).
[[gnu::noinline]] void copy_message(char* to, const char* what) {
  std::snprintf(to, kMessageSize, "%s", what ? what : "unknown error");
  for (char* c = to; *c; ++c)
    if (static_cast<unsigned char>(*c) < 32 || static_cast<unsigned char>(*c) >= 127) *c = '?';
}

[[gnu::noinline]] void size_message(char* to, std::uint64_t w, std::uint64_t h,
                                    std::uint64_t max_pixels) {
  const auto side = static_cast<unsigned long long>(std::llround(std::sqrt(double(max_pixels))));
  char limit[64];
  if (side * side == max_pixels)
    std::snprintf(limit, sizeof limit, "%llux%llu", side, side);
  else
    std::snprintf(limit, sizeof limit, "%llu pixels", static_cast<unsigned long long>(max_pixels));
  std::snprintf(to, kMessageSize, "image header says %llux%llu pixels (expected at most %s)",
                static_cast<unsigned long long>(w), static_cast<unsigned long long>(h), limit);
}

bool little_endian() {
  const std::uint16_t one = 1;
  unsigned char first;
  std::memcpy(&first, &one, 1);
  return first == 1;
}

// ---- PNG -------------------------------------------------------------------------------------

// libpng's error handler: keeps the message (error_ptr is a kMessageSize buffer), jumps back.
[[noreturn]] void png_on_error(png_structp png, png_const_charp what) {
  copy_message(static_cast<char*>(png_get_error_ptr(png)), what);
  png_longjmp(png, 1);
}
// Warnings (bad ancillary chunks, ...) are not errors; libpng's default prints them to stderr.
void png_on_warning(png_structp, png_const_charp) {}

// Creates the libpng structs of c (a PngReader or PngWriter) with create (png_create_read_struct
// or png_create_write_struct), errors kept in c.message; false ("out of memory") if it cannot.
template <typename Codec, typename Create>
bool create_png(Codec& c, Create create) {
  c.png = create(PNG_LIBPNG_VER_STRING, c.message, png_on_error, png_on_warning);
  if (!c.png) {
    copy_message(c.message, "out of memory");
    return false;
  }
  c.info = png_create_info_struct(c.png);
  if (!c.info) {
    copy_message(c.message, "out of memory");
    return false;
  }
  return true;
}

struct PngReader {
  png_structp png = nullptr;
  png_infop info = nullptr;
  char message[kMessageSize] = "";
  bool own_message = false;  // message is the whole reason (not libpng's words)
  ~PngReader() {
    if (png) png_destroy_read_struct(&png, info ? &info : nullptr, nullptr);
  }
};

// The transformations and channel layout of OpenCV's PNG decoder with IMREAD_UNCHANGED.
bool decode_png(PngReader& r, std::FILE* f, cv::Mat& out, std::uint64_t max_pixels) {
  if (!create_png(r, png_create_read_struct)) return false;
  if (setjmp(png_jmpbuf(r.png))) return false;
  // libpng refuses images wider or higher than 1,000,000 pixels by default; a label PNG of an
  // unorganized cloud is one row of a pixel per point. max_pixels is the guard instead.
  png_set_user_limits(r.png, PNG_UINT_31_MAX, PNG_UINT_31_MAX);
  png_init_io(r.png, f);
  png_read_info(r.png, r.info);
  png_uint_32 w = 0, h = 0;
  int bit_depth = 0, colour = 0;
  png_get_IHDR(r.png, r.info, &w, &h, &bit_depth, &colour, nullptr, nullptr, nullptr);
  if (std::uint64_t{w} * h > max_pixels) {
    size_message(r.message, w, h, max_pixels);
    r.own_message = true;
    return false;
  }
  const bool trns = png_get_valid(r.png, r.info, PNG_INFO_tRNS) != 0;
  int channels = 1;
  switch (colour) {
    case PNG_COLOR_TYPE_RGB:
    case PNG_COLOR_TYPE_PALETTE:
      channels = trns ? 4 : 3;
      break;
    case PNG_COLOR_TYPE_GRAY_ALPHA:
    case PNG_COLOR_TYPE_RGB_ALPHA:
      channels = 4;
      break;
    default:
      channels = 1;
  }
  const bool sixteen = bit_depth == 16;
  if (sixteen && little_endian()) png_set_swap(r.png);
  if (channels < 4)
    png_set_strip_alpha(r.png);
  else
    png_set_tRNS_to_alpha(r.png);
  if (colour == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(r.png);
  if ((colour & PNG_COLOR_MASK_COLOR) == 0 && bit_depth < 8) png_set_expand_gray_1_2_4_to_8(r.png);
  if (colour & PNG_COLOR_MASK_COLOR)
    png_set_bgr(r.png);
  else if (channels > 1)
    png_set_gray_to_rgb(r.png);
  const int passes = png_set_interlace_handling(r.png);
  png_read_update_info(r.png, r.info);
  const std::size_t row_bytes = std::size_t{w} * channels * (sixteen ? 2 : 1);
  if (png_get_rowbytes(r.png, r.info) != row_bytes || png_get_channels(r.png, r.info) != channels) {
    copy_message(r.message, "unsupported pixel layout");
    return false;
  }
  bool allocated = true;
  try {
    out.create(static_cast<int>(h), static_cast<int>(w),
               CV_MAKETYPE(sixteen ? CV_16U : CV_8U, channels));
  } catch (...) {
    allocated = false;
  }
  if (!allocated) {
    copy_message(r.message, "out of memory for the pixels");
    return false;
  }
  // Interlaced images: every pass adds its pixels to the rows ("sparkle" mode of png_read_row).
  for (int pass = 0; pass < passes; ++pass)
    for (png_uint_32 y = 0; y < h; ++y)
      png_read_row(r.png, out.ptr<png_byte>(static_cast<int>(y)), nullptr);
  png_read_end(r.png, nullptr);
  return true;
}

// ---- JPEG ------------------------------------------------------------------------------------

struct JpegError {
  jpeg_error_mgr pub;  // first: libjpeg's cinfo->err points here
  std::jmp_buf jump;
  char message[kMessageSize];
};

[[noreturn]] void jpeg_on_error(j_common_ptr cinfo) {
  auto* e = reinterpret_cast<JpegError*>(cinfo->err);
  char text[JMSG_LENGTH_MAX] = "";
  (*cinfo->err->format_message)(cinfo, text);
  copy_message(e->message, text);
  std::longjmp(e->jump, 1);
}
// Warnings (corrupt data that libjpeg recovers from, as OpenCV accepts): libjpeg's default
// prints the first to stderr.
void jpeg_quiet(j_common_ptr) {}

struct JpegReader {
  jpeg_decompress_struct cinfo{};
  JpegError err{};
  bool own_message = false;
  ~JpegReader() { jpeg_destroy_decompress(&cinfo); }  // safe on a zeroed or failed cinfo
};

// The output of OpenCV's JPEG decoder with IMREAD_UNCHANGED (libjpeg-turbo, no EXIF rotation).
bool decode_jpeg(JpegReader& r, std::FILE* f, cv::Mat& out, std::uint64_t max_pixels) {
  r.cinfo.err = jpeg_std_error(&r.err.pub);
  r.err.pub.error_exit = jpeg_on_error;
  r.err.pub.output_message = jpeg_quiet;
  if (setjmp(r.err.jump)) return false;
  jpeg_create_decompress(&r.cinfo);
  jpeg_stdio_src(&r.cinfo, f);
  jpeg_read_header(&r.cinfo, TRUE);
  if (std::uint64_t{r.cinfo.image_width} * r.cinfo.image_height > max_pixels) {
    size_message(r.err.message, r.cinfo.image_width, r.cinfo.image_height, max_pixels);
    r.own_message = true;
    return false;
  }
  const bool grey = r.cinfo.num_components == 1;
  const bool cmyk = r.cinfo.num_components == 4;
  if (grey)
    r.cinfo.out_color_space = JCS_GRAYSCALE;
  else if (cmyk)
    r.cinfo.out_color_space = JCS_CMYK;
  else
#ifdef JCS_EXTENSIONS
    r.cinfo.out_color_space = JCS_EXT_BGR;
#else
    r.cinfo.out_color_space = JCS_RGB;
#endif
  jpeg_start_decompress(&r.cinfo);
  const int w = static_cast<int>(r.cinfo.output_width), h = static_cast<int>(r.cinfo.output_height);
  const int components = grey ? 1 : cmyk ? 4 : 3;
  if (r.cinfo.output_components != components) {
    copy_message(r.err.message, "unsupported colour layout");
    return false;
  }
  bool allocated = true;
  try {
    out.create(h, w, grey ? CV_8UC1 : CV_8UC3);
  } catch (...) {
    allocated = false;
  }
  if (!allocated) {
    copy_message(r.err.message, "out of memory for the pixels");
    return false;
  }
  // CMYK rows go through a buffer of libjpeg's (freed with cinfo).
  JSAMPARRAY cmyk_row =
      cmyk ? (*r.cinfo.mem->alloc_sarray)(reinterpret_cast<j_common_ptr>(&r.cinfo), JPOOL_IMAGE,
                                          static_cast<JDIMENSION>(w) * 4, 1)
           : nullptr;
  while (r.cinfo.output_scanline < r.cinfo.output_height) {
    const int y = static_cast<int>(r.cinfo.output_scanline);
    JSAMPROW row = cmyk ? cmyk_row[0] : out.ptr<JSAMPLE>(y);
    if (jpeg_read_scanlines(&r.cinfo, &row, 1) != 1) {
      copy_message(r.err.message, "decoder stopped early");
      return false;
    }
    if (cmyk) {
      std::uint8_t* bgr = out.ptr<std::uint8_t>(y);
      for (int x = 0; x < w; ++x, bgr += 3) {
        const int c = row[4 * x], m = row[4 * x + 1], ye = row[4 * x + 2], k = row[4 * x + 3];
        bgr[2] = static_cast<std::uint8_t>(k - ((255 - c) * k >> 8));
        bgr[1] = static_cast<std::uint8_t>(k - ((255 - m) * k >> 8));
        bgr[0] = static_cast<std::uint8_t>(k - ((255 - ye) * k >> 8));
      }
    }
#ifndef JCS_EXTENSIONS
    if (!grey && !cmyk) {
      std::uint8_t* p = out.ptr<std::uint8_t>(y);
      for (int x = 0; x < w; ++x) std::swap(p[3 * x], p[3 * x + 2]);
    }
#endif
  }
  jpeg_finish_decompress(&r.cinfo);
  return true;
}

// ---- PNG encoding ----------------------------------------------------------------------------

struct PngWriter {
  png_structp png = nullptr;
  png_infop info = nullptr;
  char message[kMessageSize] = "";
  std::string bytes;
  ~PngWriter() {
    if (png) png_destroy_write_struct(&png, info ? &info : nullptr);
  }
};

void png_append(png_structp png, png_bytep data, png_size_t size) {
  auto* w = static_cast<PngWriter*>(png_get_io_ptr(png));
  bool ok = true;
  try {
    w->bytes.append(reinterpret_cast<const char*>(data), size);
  } catch (...) {
    ok = false;
  }
  if (!ok) png_error(png, "out of memory");
}
void png_no_flush(png_structp) {}

// The calls and settings of OpenCV's PNG encoder with its default parameters, for 8-bit BGR
// (written as RGB) or 16-bit grey (written big-endian).
bool encode(PngWriter& w, const cv::Mat& image) {
  if (!create_png(w, png_create_write_struct)) return false;
  if (setjmp(png_jmpbuf(w.png))) return false;
  png_set_write_fn(w.png, &w, png_append, png_no_flush);
  png_set_user_limits(w.png, PNG_UINT_31_MAX, PNG_UINT_31_MAX);  // as in decode_png
  png_set_filter(w.png, PNG_FILTER_TYPE_BASE, PNG_FILTER_SUB);
  png_set_compression_level(w.png, Z_BEST_SPEED);
  png_set_compression_strategy(w.png, Z_RLE);
  const bool grey16 = image.type() == CV_16UC1;
  png_set_IHDR(w.png, w.info, static_cast<png_uint_32>(image.cols),
               static_cast<png_uint_32>(image.rows), grey16 ? 16 : 8,
               grey16 ? PNG_COLOR_TYPE_GRAY : PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_write_info(w.png, w.info);
  if (grey16) {
    // libpng swaps each row to the file's big-endian order on a little-endian machine.
    if (little_endian()) png_set_swap(w.png);
  } else {
    png_set_bgr(w.png);
  }
  for (int y = 0; y < image.rows; ++y) png_write_row(w.png, image.ptr<png_byte>(y));
  png_write_end(w.png, w.info);
  return true;
}

// The PNG bytes of an image encode takes; std::runtime_error if libpng fails.
std::string png_bytes(const cv::Mat& image) {
  PngWriter w;
  if (!encode(w, image))
    throw std::runtime_error(std::string("PNG encoding failed (") + w.message + ")");
  return std::move(w.bytes);
}

}  // namespace

cv::Mat read_image_file(const std::string& path, std::uint64_t max_pixels) {
  const std::unique_ptr<std::FILE, int (*)(std::FILE*)> f(std::fopen(path.c_str(), "rbe"),
                                                          &std::fclose);
  if (!f) throw std::runtime_error(std::string("cannot open (") + std::strerror(errno) + ")");
  const int first = std::getc(f.get());
  if (first == EOF)
    throw std::runtime_error(std::ferror(f.get())
                                 ? std::string("cannot read image (") + std::strerror(errno) + ")"
                                 : std::string("cannot read image (empty file; expected a PNG or "
                                               "JPEG)"));
  std::ungetc(first, f.get());
  cv::Mat out;
  if (first == 0x89) {
    PngReader r;
    if (!decode_png(r, f.get(), out, max_pixels))
      throw std::runtime_error(r.own_message ? std::string(r.message)
                                             : "cannot decode PNG (" + std::string(r.message) +
                                                   "; expected a complete, valid PNG)");
  } else if (first == 0xFF) {
    JpegReader r;
    if (!decode_jpeg(r, f.get(), out, max_pixels))
      throw std::runtime_error(r.own_message ? std::string(r.err.message)
                                             : "cannot decode JPEG (" + std::string(r.err.message) +
                                                   "; expected a complete, valid JPEG)");
  } else {
    throw std::runtime_error("cannot read image (expected a PNG or JPEG)");
  }
  return out;
}

std::string encode_png(const cv::Mat& bgr) {
  if (bgr.type() != CV_8UC3 || bgr.empty())
    throw std::invalid_argument("encode_png: expected a non-empty 8-bit 3-channel image");
  return png_bytes(bgr);
}

std::string encode_png16(const cv::Mat& grey16) {
  if (grey16.type() != CV_16UC1 || grey16.empty())
    throw std::invalid_argument("encode_png16: expected a non-empty 16-bit 1-channel image");
  return png_bytes(grey16);
}

}  // namespace proxseg::detail
