#pragma once
// Pictures for MuJoCo textures. MuJoCo 2.2 reads PNG only: a picture in another format OpenCV
// reads (JPEG, BMP, TIFF, ...) is converted once into a cache directory, never beside the user's
// file: $NUDGE_TEXTURE_CACHE, else the first writable of $XDG_CACHE_HOME/nudge/textures and
// ~/.cache/nudge/textures, else /tmp/nudge-textures-<uid>.
#include <stdexcept>
#include <string>

namespace nudge::sim {

class TextureError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

std::string texture_cache_dir();

// True if the file starts like a picture OpenCV can decode (its signature; the file is not decoded).
bool is_image_file(const std::string& path);

// A PNG file MuJoCo can load showing the picture `path`: `path` itself if it is a PNG with a name
// safe in MJCF, else a converted copy in the cache named by a hash of the picture's bytes (written
// to a temporary name and renamed, so a crash never leaves a half-written PNG there). Throws
// TextureError naming the file when it cannot be read or decoded, or the cache cannot be written.
std::string png_texture(const std::string& path);

}  // namespace nudge::sim
