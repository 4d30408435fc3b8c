#pragma once
// Reading an image file without trusting it: the PNG/JPEG header is read first (nudge/image_header.hpp),
// so a huge declared size or a truncated file is refused before any pixel is decoded.
#include <opencv2/core.hpp>

#include <stdexcept>
#include <string>

namespace nudge::camera {

class ImageFileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Reads and decodes `path` (cv::imread flags, e.g. cv::IMREAD_COLOR). PNG and JPEG files are checked
// (size at most max_pixels, data complete) before decoding; other formats OpenCV reads are decoded
// as they are. Throws ImageFileError naming the file and the problem.
cv::Mat read_image_file(const std::string& path, int imread_flags, int64_t max_pixels = int64_t{64} * 1024 * 1024);

}  // namespace nudge::camera
