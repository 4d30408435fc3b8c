#pragma once
// Reading a PNG or JPEG's header before decoding its pixels, so that a small file declaring a huge
// image (a 389 KB PNG of 20000x20000 decodes to 1.2 GB) is refused before any allocation, and a
// truncated file is refused instead of decoded into half an image. No OpenCV: only the bytes.
#include <cstddef>
#include <cstdint>
#include <string>

namespace nudge {

// The largest image accepted from a file or a message: 64 Mpixel (16 x a 2048x2048 frame).
constexpr int64_t kMaxImagePixels = int64_t{64} * 1024 * 1024;

struct ImageHeader {
  enum class Format { Unknown, Png, Jpeg };
  Format format = Format::Unknown;
  int64_t width = 0, height = 0;
  bool complete = false;  // PNG: ends with its IEND chunk; JPEG: an end-of-image marker follows the scan
};

// Parses the signature and the size-bearing header (PNG IHDR, JPEG SOFn). Format::Unknown when
// the bytes are neither a PNG nor a JPEG or the header is cut short.
ImageHeader read_image_header(const uint8_t* data, size_t size);

// Why these bytes must not be decoded: not a PNG/JPEG, a header without a size, more than
// max_pixels pixels, or data cut short. "" when they may be decoded.
std::string check_compressed_image(const uint8_t* data, size_t size, int64_t max_pixels = kMaxImagePixels);

}  // namespace nudge
