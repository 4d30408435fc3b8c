#include "nudge/sim/textures.hpp"

#include <opencv2/imgcodecs.hpp>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <unistd.h>
#include <vector>

namespace nudge::sim {

namespace {

std::string env(const char* name) {
  const char* v = std::getenv(name);
  return v && *v ? std::string(v) : std::string();
}

std::vector<unsigned char> read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw TextureError(path + ": cannot read the picture");
  return std::vector<unsigned char>(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

bool starts_like_png(const std::vector<unsigned char>& bytes) {
  static const unsigned char magic[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  return bytes.size() >= 8 && std::equal(magic, magic + 8, bytes.begin());
}

// FNV-1a: names a converted picture by its content, so an edited picture gets a new cache entry.
uint64_t fnv1a(const std::vector<unsigned char>& bytes) {
  uint64_t h = 1469598103934665603ULL;
  for (unsigned char b : bytes) {
    h ^= b;
    h *= 1099511628211ULL;
  }
  return h;
}

}  // namespace

std::string texture_cache_dir() {
  if (const std::string dir = env("NUDGE_TEXTURE_CACHE"); !dir.empty()) return dir;
  // The first of the usual places that exists or can be made (a CI user may have no writable home).
  std::vector<std::string> candidates;
  if (const std::string xdg = env("XDG_CACHE_HOME"); !xdg.empty()) candidates.push_back(xdg + "/nudge/textures");
  if (const std::string home = env("HOME"); !home.empty()) candidates.push_back(home + "/.cache/nudge/textures");
  for (const std::string& dir : candidates) {
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    if (!ec && ::access(dir.c_str(), W_OK) == 0) return dir;
  }
  return "/tmp/nudge-textures-" + std::to_string(::getuid());
}

bool is_image_file(const std::string& path) {
  try {
    return cv::haveImageReader(path);
  } catch (const cv::Exception&) {
    return false;
  }
}

std::string png_texture(const std::string& path) {
  const std::vector<unsigned char> bytes = read_bytes(path);
  if (starts_like_png(bytes) && path.find_first_of("\"<>&") == std::string::npos) return path;
  const cv::Mat picture = cv::imdecode(bytes, cv::IMREAD_COLOR);
  if (picture.empty()) throw TextureError(path + ": not a picture OpenCV can decode (PNG or JPEG)");
  std::ostringstream name;
  name << std::hex << fnv1a(bytes) << ".png";
  const std::filesystem::path dir = texture_cache_dir();
  const std::filesystem::path target = dir / name.str();
  std::error_code ec;
  if (std::filesystem::exists(target, ec)) return target.string();
  std::filesystem::create_directories(dir, ec);
  if (ec) throw TextureError(path + ": cannot make the texture cache " + dir.string() + ": " + ec.message());
  const std::filesystem::path temporary =
      dir / (name.str() + ".tmp" + std::to_string(::getpid()) + ".png");
  if (!cv::imwrite(temporary.string(), picture)) {
    std::filesystem::remove(temporary, ec);
    throw TextureError(path + ": cannot write its PNG copy " + temporary.string());
  }
  std::filesystem::rename(temporary, target, ec);
  if (ec) {
    std::filesystem::remove(temporary, ec);
    throw TextureError(path + ": cannot move its PNG copy into " + dir.string());
  }
  return target.string();
}

}  // namespace nudge::sim
