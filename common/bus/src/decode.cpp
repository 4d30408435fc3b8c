#include "nudge/bus/decode.hpp"

#include <cstdint>
#include <map>
#include <vector>

namespace nudge::bus {

namespace {

// Reads the big-endian fields of an LCM encoding in order, remembering whether it ran out.
class WireReader {
 public:
  WireReader(const void* data, int size) : data_(static_cast<const uint8_t*>(data)), size_(size) {}

  int64_t left() const { return size_ - pos_; }
  // An LCM string: its length (with the terminating NUL, so at least 1) and its bytes.
  bool skip_string() {
    int32_t length = 0;
    return read_int32(&length) && length >= 1 && skip(length);
  }
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

namespace {

// Where the element count of a message's variable-length array sits: the fixed-size fields and
// strings before it, and the fewest encoded bytes one element takes. Every type a service
// accepts that has such an array is here; nested arrays (inside the elements) are not checked.
struct Field {
  enum Kind { Fixed, String, Count } kind;
  int bytes;               // Fixed: its size; Count: the least encoded bytes of one element
  const char* name = "";   // String, Count: the field's name, for the error
};
const std::map<std::string, std::vector<Field>>& array_layouts() {
  constexpr int kPose = 7 * 8, kSymmetryLine = 12 * 4;
  static const std::map<std::string, std::vector<Field>> layouts = {
      // fingerprint, utime, seq, command, target, direction, height, angle, speed_scale
      {"arm_command_t", {{Field::Fixed, 8 + 8 + 8 + 1 + kPose + 24 + 8 + 8 + 8}, {Field::Count, 8, "num_joints"}}},
      // fingerprint, utime, frames_used, intersects; position[n][3] and cluster_size[n]
      {"candidates_t", {{Field::Fixed, 8 + 8 + 4 + 4}, {Field::Count, 3 * 8 + 4, "num_candidates"}}},
      {"axes_t", {{Field::Fixed, 8 + 8 + 4}, {Field::Count, 1, "num_axes"}}},
      // ..., camera, width, height, num_edges, ms_edges, ms_vote, ms_peaks
      {"symmetry_lines_t",
       {{Field::Fixed, 8 + 8 + 8}, {Field::String, 0, "camera"}, {Field::Fixed, 6 * 4}, {Field::Count, kSymmetryLine, "num_lines"}}},
      // ..., camera, status, reason, line, covariance, box, block_size, blocks_w, blocks_h
      {"track_t",
       {{Field::Fixed, 8 + 8 + 8}, {Field::String, 0, "camera"}, {Field::Fixed, 1}, {Field::String, 0, "reason"},
        {Field::Fixed, kSymmetryLine + 4 * 4 + 8 * 4 + 3 * 4}, {Field::Count, 1, "num_blocks"}}},
      // fingerprint, utime, step, joints[6], gripper
      {"sim_state_t", {{Field::Fixed, 8 + 8 + 8 + 6 * 8 + 8}, {Field::Count, 1, "num_objects"}}},
      {"contours_t", {{Field::Fixed, 8 + 8 + 8}, {Field::String, 0, "camera"}, {Field::Count, 1, "num_contours"}}},
      // ..., seq, label, reason, best_view, learned_utime; names[n] (each at least a length and
      // a NUL) and matches[n]. The match_picture image after them is not checked.
      {"recognition_t",
       {{Field::Fixed, 8 + 8 + 8}, {Field::String, 0, "label"}, {Field::String, 0, "reason"}, {Field::Fixed, 4 + 8},
        {Field::Count, 5 + 4, "num_objects"}}},
      // Messages that end in an image_t (nested: no fingerprint of its own): utime, frame_id,
      // camera, width, height, row_stride, pixel_format, then size bytes of data.
      // fingerprint, utime, run_id, object_key, view_index, wrist_angle, box[4]
      {"learn_view_t",
       {{Field::Fixed, 8 + 8}, {Field::String, 0, "run_id"}, {Field::String, 0, "object_key"}, {Field::Fixed, 4 + 8 + 16},
        {Field::Fixed, 8 + 8}, {Field::String, 0, "image.camera"}, {Field::Fixed, 3 * 4 + 1}, {Field::Count, 1, "image.size"}}},
      // fingerprint, utime, seq, roi[4], want_match_picture
      {"recognize_request_t",
       {{Field::Fixed, 8 + 8 + 8 + 16 + 1}, {Field::Fixed, 8 + 8}, {Field::String, 0, "image.camera"}, {Field::Fixed, 3 * 4 + 1},
        {Field::Count, 1, "image.size"}}},
  };
  return layouts;
}

}  // namespace

std::string check_declared_lengths(const std::string& type_name, const void* data, int size_bytes) {
  const auto layout = array_layouts().find(type_name);
  if (layout == array_layouts().end()) return {};
  WireReader in(data, size_bytes);
  const std::string name = type_name + " of " + std::to_string(size_bytes) + " bytes: ";
  for (const Field& field : layout->second) {
    if (field.kind == Field::Fixed && !in.skip(field.bytes)) return name + "too short";
    if (field.kind == Field::String && !in.skip_string()) return name + field.name + " has a bad length";
    if (field.kind == Field::Count) {
      int32_t count = 0;
      if (!in.read_int32(&count)) return name + "too short";
      if (count < 0 || static_cast<int64_t>(count) * field.bytes > in.left())
        return name + field.name + " declares " + std::to_string(count) + " elements, " + std::to_string(in.left()) +
               " bytes left";
    }
  }
  return {};
}

}  // namespace nudge::bus
