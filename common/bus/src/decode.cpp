#include "nudge/bus/decode.hpp"

#include <cstdint>

namespace nudge::bus {

namespace {

// Reads the big-endian fields of an LCM encoding in order, remembering whether it ran out.
class WireReader {
 public:
  WireReader(const void* data, int size) : data_(static_cast<const uint8_t*>(data)), size_(size) {}

  int64_t left() const { return size_ - pos_; }
  bool skip(int64_t bytes) {
    if (bytes < 0 || bytes > left()) return false;
    pos_ += bytes;
    return true;
  }
  bool read_int32(int32_t* value) {
    if (left() < 4) return false;
    uint32_t v = 0;
    for (int i = 0; i < 4; ++i) v = (v << 8) | data_[pos_ + i];
    *value = static_cast<int32_t>(v);
    pos_ += 4;
    return true;
  }

 private:
  const uint8_t* data_;
  int64_t size_;
  int64_t pos_ = 0;
};

}  // namespace

std::string check_encoded_image(const void* data, int size_bytes) {
  WireReader in(data, size_bytes);
  const std::string name = "image_t of " + std::to_string(size_bytes) + " bytes: ";
  // fingerprint, utime, frame_id
  if (!in.skip(8 + 8 + 8)) return name + "too short";
  int32_t camera_length = 0;
  if (!in.read_int32(&camera_length)) return name + "too short";
  // An LCM string's length counts its terminating NUL: it is at least 1.
  if (camera_length < 1 || camera_length > in.left())
    return name + "camera declares " + std::to_string(camera_length) + " bytes, " + std::to_string(in.left()) + " left";
  in.skip(camera_length);
  // width, height, row_stride, pixel_format
  if (!in.skip(4 + 4 + 4 + 1)) return name + "too short";
  int32_t payload = 0;
  if (!in.read_int32(&payload)) return name + "too short";
  if (payload < 0 || payload > in.left())
    return name + "size declares " + std::to_string(payload) + " data bytes, " + std::to_string(in.left()) + " left";
  return {};
}

}  // namespace nudge::bus
