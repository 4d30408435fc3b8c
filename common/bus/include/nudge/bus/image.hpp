#pragma once
// image_t <-> cv::Mat for GRAY8 / RGB8 / BGR8 and MJPEG / PNG compressed images.
#include <opencv2/core.hpp>

#include <stdexcept>
#include <string>

#include "nudge/image_t.hpp"

namespace nudge::bus {

class ImageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Decodes to an 8-bit BGR or grey cv::Mat (RGB8 is converted to BGR). Throws ImageError naming the
// image (camera, frame id) and the problem: unknown format, sizes that disagree, undecodable data.
cv::Mat to_mat(const nudge::image_t& msg);

// Encodes an 8-bit grey or BGR image. format is one of image_t::FORMAT_*.
nudge::image_t to_message(const cv::Mat& image, int8_t format, int64_t utime, int64_t frame_id,
                          const std::string& camera, int jpeg_quality = 90);

// "gray", "bgr", "rgb", "jpeg", "png" -> image_t::FORMAT_*; throws ImageError for other names.
int8_t format_from_name(const std::string& name);
std::string format_name(int8_t format);

}  // namespace nudge::bus
