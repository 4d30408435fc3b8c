#include "binary_io.hpp"

#include <cstdint>
#include <cstring>
#include <stdexcept>

namespace nudge::learning::detail {

namespace {

constexpr char kMagic[8] = {'N', 'U', 'D', 'G', 'E', 'F', 'T', '1'};
// Version 1: keypoints and descriptors; 2 adds each keypoint's colour (Features::colours).
constexpr uint32_t kFirstVersionWithColours = 2;

uint64_t fnv1a(const char* data, size_t size) {
  uint64_t h = 1469598103934665603ull;
  for (size_t i = 0; i < size; ++i) {
    h ^= static_cast<unsigned char>(data[i]);
    h *= 1099511628211ull;
  }
  return h;
}

template <typename T>
void put(std::string& out, T value) {
  out.append(reinterpret_cast<const char*>(&value), sizeof value);
}

class Reader {
 public:
  Reader(const std::string& bytes, size_t end) : bytes_(bytes), end_(end) {}
  template <typename T>
  T get() {
    T value;
    need(sizeof value);
    std::memcpy(&value, bytes_.data() + pos_, sizeof value);
    pos_ += sizeof value;
    return value;
  }
  void read(void* into, size_t size) {
    need(size);
    std::memcpy(into, bytes_.data() + pos_, size);
    pos_ += size;
  }
  bool at_end() const { return pos_ == end_; }

 private:
  void need(size_t size) const {
    if (size > end_ - pos_) throw std::runtime_error("truncated");
  }
  const std::string& bytes_;
  size_t end_, pos_ = 0;
};

}  // namespace

std::string encode_features(const std::vector<const Features*>& views, int format_version) {
  std::string out(kMagic, sizeof kMagic);
  put<uint32_t>(out, static_cast<uint32_t>(format_version));
  put<uint32_t>(out, static_cast<uint32_t>(views.size()));
  for (const Features* f : views) {
    const int dims = f->descriptors.empty() ? 128 : f->descriptors.cols;
    put<uint32_t>(out, static_cast<uint32_t>(f->size()));
    put<uint32_t>(out, static_cast<uint32_t>(dims));
    for (const cv::KeyPoint& k : f->keypoints) {
      for (float v : {k.pt.x, k.pt.y, k.size, k.angle, k.response}) put<float>(out, v);
      put<int32_t>(out, k.octave);
      put<int32_t>(out, k.class_id);
    }
    for (int r = 0; r < f->descriptors.rows; ++r)
      out.append(reinterpret_cast<const char*>(f->descriptors.ptr<float>(r)), dims * sizeof(float));
    if (static_cast<uint32_t>(format_version) < kFirstVersionWithColours) continue;
    // Version 2: the keypoints' colours, 3 values each, or 0 when the view has none.
    const bool coloured = f->colours.rows == f->size() && f->size() > 0;
    put<uint32_t>(out, coloured ? 3u : 0u);
    for (int r = 0; coloured && r < f->colours.rows; ++r)
      out.append(reinterpret_cast<const char*>(f->colours.ptr<float>(r)), 3 * sizeof(float));
  }
  put<uint64_t>(out, fnv1a(out.data(), out.size()));
  return out;
}

std::vector<Features> decode_features(const std::string& bytes, int max_format_version) {
  if (bytes.size() < sizeof kMagic + 8 + 8 || std::memcmp(bytes.data(), kMagic, sizeof kMagic) != 0)
    throw std::runtime_error("not a features file (bad magic or too short)");
  const size_t body = bytes.size() - sizeof(uint64_t);
  uint64_t stored;
  std::memcpy(&stored, bytes.data() + body, sizeof stored);
  Reader in(bytes, body);
  char magic[sizeof kMagic];
  in.read(magic, sizeof magic);
  const auto version = in.get<uint32_t>();
  if (version > static_cast<uint32_t>(max_format_version))
    throw std::runtime_error("format version " + std::to_string(version) + " is newer than this program reads (" +
                             std::to_string(max_format_version) + ")");
  if (stored != fnv1a(bytes.data(), body)) throw std::runtime_error("checksum mismatch (corrupt)");
  const auto view_count = in.get<uint32_t>();
  std::vector<Features> views;
  for (uint32_t v = 0; v < view_count; ++v) {
    const auto n = in.get<uint32_t>();
    const auto dims = in.get<uint32_t>();
    if (dims != 128) throw std::runtime_error("view " + std::to_string(v) + ": descriptors of " + std::to_string(dims) + " values, not 128");
    if (n > body) throw std::runtime_error("view " + std::to_string(v) + ": impossible keypoint count");
    Features f;
    for (uint32_t i = 0; i < n; ++i) {
      cv::KeyPoint k;
      k.pt.x = in.get<float>();
      k.pt.y = in.get<float>();
      k.size = in.get<float>();
      k.angle = in.get<float>();
      k.response = in.get<float>();
      k.octave = in.get<int32_t>();
      k.class_id = in.get<int32_t>();
      f.keypoints.push_back(k);
    }
    f.descriptors.create(static_cast<int>(n), static_cast<int>(dims), CV_32F);
    if (n > 0) in.read(f.descriptors.data, static_cast<size_t>(n) * dims * sizeof(float));
    if (version >= kFirstVersionWithColours) {
      const auto channels = in.get<uint32_t>();
      if (channels != 0 && channels != 3)
        throw std::runtime_error("view " + std::to_string(v) + ": colours of " + std::to_string(channels) + " values, not 3");
      if (channels == 3) {
        f.colours.create(static_cast<int>(n), 3, CV_32F);
        in.read(f.colours.data, static_cast<size_t>(n) * 3 * sizeof(float));
      }
    }
    views.push_back(std::move(f));
  }
  if (!in.at_end()) throw std::runtime_error("trailing bytes after the last view");
  return views;
}

}  // namespace nudge::learning::detail
