#include "nudge/camera/image_file.hpp"

#include <filesystem>
#include <fstream>
#include <iterator>
#include <opencv2/imgcodecs.hpp>
#include <vector>

#include "nudge/image_header.hpp"

namespace nudge::camera {

cv::Mat read_image_file(const std::string& path, int imread_flags, int64_t max_pixels) {
  const auto fail = [&](const std::string& why) { return ImageFileError(path + ": cannot read the image (" + why + ")"); };
  std::error_code error;
  if (std::filesystem::is_directory(path, error)) throw fail("a directory, not an image file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw fail("missing or unreadable");
  const std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (bytes.empty()) throw fail("the file is empty");
  const bool png_or_jpeg = bytes.size() >= 2 && ((bytes[0] == 0x89 && bytes[1] == 'P') ||
                                                  (bytes[0] == 0xFF && bytes[1] == 0xD8));
  if (png_or_jpeg) {  // by its signature: then its header must be sound
    const std::string problem = check_compressed_image(bytes.data(), bytes.size(), max_pixels);
    if (!problem.empty()) throw fail(problem);
  }
  cv::Mat image = cv::imdecode(bytes, imread_flags);
  if (image.empty()) throw fail("not an image OpenCV decodes");
  return image;
}

}  // namespace nudge::camera
