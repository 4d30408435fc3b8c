#include "nudge/image_header.hpp"

#include <cstring>

namespace nudge {

namespace {

uint32_t big_endian32(const uint8_t* p) {
  return (uint32_t{p[0]} << 24) | (uint32_t{p[1]} << 16) | (uint32_t{p[2]} << 8) | uint32_t{p[3]};
}
uint32_t big_endian16(const uint8_t* p) { return (uint32_t{p[0]} << 8) | uint32_t{p[1]}; }

ImageHeader read_png(const uint8_t* data, size_t size) {
  ImageHeader header;
  // signature (8), IHDR length (4), "IHDR" (4), width (4), height (4)
  if (size < 24 || std::memcmp(data + 12, "IHDR", 4) != 0) return header;
  header.format = ImageHeader::Format::Png;
  header.width = big_endian32(data + 16);
  header.height = big_endian32(data + 20);
  // the last chunk: length 0, "IEND", CRC
  header.complete = size >= 12 + 24 && std::memcmp(data + size - 8, "IEND", 4) == 0;
  return header;
}

// SOF0..SOF15 carry the frame size; C4 (DHT), C8 (JPG) and CC (DAC) share the range but do not.
bool is_start_of_frame(uint8_t marker) {
  return marker >= 0xC0 && marker <= 0xCF && marker != 0xC4 && marker != 0xC8 && marker != 0xCC;
}
// Markers without a length field: TEM and the restart markers.
bool is_standalone(uint8_t marker) { return marker == 0x01 || (marker >= 0xD0 && marker <= 0xD7); }

// Entropy-coded data escapes 0xFF as FF 00 and uses FF D0..D7 for restarts, so the first FF D9
// after the start of the first scan is the end-of-image marker.
bool has_end_of_image(const uint8_t* data, size_t size, size_t from) {
  for (size_t i = from; i + 1 < size; ++i)
    if (data[i] == 0xFF && data[i + 1] == 0xD9) return true;
  return false;
}

ImageHeader read_jpeg(const uint8_t* data, size_t size) {
  ImageHeader header;
  size_t pos = 2;  // after SOI
  bool have_size = false;
  while (pos + 4 <= size) {
    if (data[pos] != 0xFF) return {};  // not a marker where one must be
    while (pos < size && data[pos] == 0xFF) ++pos;  // fill bytes
    if (pos >= size) return {};
    const uint8_t marker = data[pos++];
    if (is_standalone(marker)) continue;
    if (pos + 2 > size) return {};
    const size_t length = big_endian16(data + pos);
    if (length < 2 || pos + length > size) return {};
    if (is_start_of_frame(marker) && !have_size) {
      if (length < 7) return {};
      header.height = big_endian16(data + pos + 3);
      header.width = big_endian16(data + pos + 5);
      have_size = true;
    }
    if (marker == 0xDA) {  // start of scan: the header is over
      if (!have_size) return {};
      header.format = ImageHeader::Format::Jpeg;
      header.complete = has_end_of_image(data, size, pos + length);
      return header;
    }
    pos += length;
  }
  return {};
}

}  // namespace

ImageHeader read_image_header(const uint8_t* data, size_t size) {
  static const uint8_t kPng[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  if (data && size >= 8 && std::memcmp(data, kPng, 8) == 0) return read_png(data, size);
  if (data && size >= 4 && data[0] == 0xFF && data[1] == 0xD8 && data[2] == 0xFF) return read_jpeg(data, size);
  return {};
}

std::string check_compressed_image(const uint8_t* data, size_t size, int64_t max_pixels) {
  const ImageHeader header = read_image_header(data, size);
  if (header.format == ImageHeader::Format::Unknown)
    return "not a PNG or JPEG, or its header is cut short (" + std::to_string(size) + " bytes)";
  const std::string name = header.format == ImageHeader::Format::Png ? "PNG" : "JPEG";
  const std::string dims = std::to_string(header.width) + "x" + std::to_string(header.height);
  if (header.width <= 0 || header.height <= 0) return name + " header declares a size of " + dims;
  // Divided, not multiplied: two 32-bit dimensions overflow an int64 product (found by fuzzing).
  if (header.width > max_pixels / header.height)
    return name + " header declares " + dims + ", more than the " + std::to_string(max_pixels) + " pixels accepted";
  if (!header.complete) return name + " data of " + std::to_string(size) + " bytes is truncated (no end marker)";
  return {};
}

}  // namespace nudge
