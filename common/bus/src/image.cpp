#include "nudge/bus/image.hpp"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "nudge/image_header.hpp"

namespace nudge::bus {

namespace {
std::string describe(const nudge::image_t& msg) {
  return "image '" + msg.camera + "' frame " + std::to_string(msg.frame_id);
}
}  // namespace

cv::Mat to_mat(const nudge::image_t& msg) {
  const int8_t f = msg.pixel_format;
  if (f == image_t::FORMAT_MJPEG || f == image_t::FORMAT_PNG) {
    if (msg.data.empty()) throw ImageError(describe(msg) + ": compressed data is empty");
    // The header first: a small message must not make us decode a huge or half image.
    const std::string problem = check_compressed_image(msg.data.data(), msg.data.size());
    if (!problem.empty()) {
      const bool known = read_image_header(msg.data.data(), msg.data.size()).format != ImageHeader::Format::Unknown;
      throw ImageError(describe(msg) + ": " + format_name(f) + " data " + (known ? "refused: " : "does not decode: ") +
                       problem);
    }
    cv::Mat decoded = cv::imdecode(msg.data, cv::IMREAD_UNCHANGED);
    if (decoded.empty()) throw ImageError(describe(msg) + ": " + format_name(f) + " data does not decode");
    if (decoded.depth() != CV_8U) throw ImageError(describe(msg) + ": only 8-bit images are supported");
    if (decoded.channels() == 4) cv::cvtColor(decoded, decoded, cv::COLOR_BGRA2BGR);
    if (msg.width > 0 && msg.height > 0 && (decoded.cols != msg.width || decoded.rows != msg.height)) {
      throw ImageError(describe(msg) + ": header says " + std::to_string(msg.width) + "x" +
                       std::to_string(msg.height) + " but the data is " + std::to_string(decoded.cols) + "x" +
                       std::to_string(decoded.rows));
    }
    return decoded;
  }
  int channels = 0;
  if (f == image_t::FORMAT_GRAY8) channels = 1;
  else if (f == image_t::FORMAT_RGB8 || f == image_t::FORMAT_BGR8) channels = 3;
  else throw ImageError(describe(msg) + ": unknown pixel format " + std::to_string(f));
  if (msg.width <= 0 || msg.height <= 0) {
    throw ImageError(describe(msg) + ": bad size " + std::to_string(msg.width) + "x" + std::to_string(msg.height));
  }
  const int64_t min_stride = static_cast<int64_t>(msg.width) * channels;
  if (msg.row_stride < min_stride) {
    throw ImageError(describe(msg) + ": row_stride " + std::to_string(msg.row_stride) + " is less than width x " +
                     std::to_string(channels) + " = " + std::to_string(min_stride));
  }
  const int64_t needed = static_cast<int64_t>(msg.row_stride) * (msg.height - 1) + min_stride;
  if (static_cast<int64_t>(msg.data.size()) < needed) {
    throw ImageError(describe(msg) + ": " + std::to_string(msg.data.size()) + " bytes of data, " +
                     std::to_string(needed) + " needed for " + std::to_string(msg.width) + "x" +
                     std::to_string(msg.height) + " " + format_name(f));
  }
  const cv::Mat view(msg.height, msg.width, CV_8UC(channels), const_cast<uint8_t*>(msg.data.data()),
                     static_cast<size_t>(msg.row_stride));
  cv::Mat out;
  if (f == image_t::FORMAT_RGB8) cv::cvtColor(view, out, cv::COLOR_RGB2BGR);
  else out = view.clone();
  return out;
}

nudge::image_t to_message(const cv::Mat& image, int8_t format, int64_t utime, int64_t frame_id,
                          const std::string& camera, int jpeg_quality) {
  if (image.empty() || image.depth() != CV_8U || (image.channels() != 1 && image.channels() != 3)) {
    throw ImageError("camera '" + camera + "': only non-empty 8-bit grey or BGR images can be sent");
  }
  nudge::image_t msg;
  msg.utime = utime;
  msg.frame_id = frame_id;
  msg.camera = camera;
  msg.width = image.cols;
  msg.height = image.rows;
  msg.pixel_format = format;
  cv::Mat pixels;  // never aliases `image`: a conversion must not write into the caller's pixels
  switch (format) {
    case image_t::FORMAT_GRAY8:
      if (image.channels() == 3) cv::cvtColor(image, pixels, cv::COLOR_BGR2GRAY);
      else pixels = image;
      break;
    case image_t::FORMAT_BGR8:
      if (image.channels() == 1) cv::cvtColor(image, pixels, cv::COLOR_GRAY2BGR);
      else pixels = image;
      break;
    case image_t::FORMAT_RGB8:
      cv::cvtColor(image, pixels, image.channels() == 1 ? cv::COLOR_GRAY2RGB : cv::COLOR_BGR2RGB);
      break;
    case image_t::FORMAT_MJPEG:
    case image_t::FORMAT_PNG: {
      std::vector<int> opts;
      if (format == image_t::FORMAT_MJPEG) opts = {cv::IMWRITE_JPEG_QUALITY, jpeg_quality};
      if (!cv::imencode(format == image_t::FORMAT_MJPEG ? ".jpg" : ".png", image, msg.data, opts)) {
        throw ImageError("camera '" + camera + "': encoding failed");
      }
      msg.row_stride = 0;
      msg.size = static_cast<int32_t>(msg.data.size());
      return msg;
    }
    default:
      throw ImageError("camera '" + camera + "': unknown pixel format " + std::to_string(format));
  }
  if (!pixels.isContinuous()) pixels = pixels.clone();
  msg.row_stride = static_cast<int32_t>(pixels.cols * pixels.channels());
  msg.data.assign(pixels.data, pixels.data + pixels.total() * pixels.channels());
  msg.size = static_cast<int32_t>(msg.data.size());
  return msg;
}

int8_t format_from_name(const std::string& name) {
  if (name == "gray" || name == "grey") return image_t::FORMAT_GRAY8;
  if (name == "bgr") return image_t::FORMAT_BGR8;
  if (name == "rgb") return image_t::FORMAT_RGB8;
  if (name == "jpeg" || name == "mjpeg") return image_t::FORMAT_MJPEG;
  if (name == "png") return image_t::FORMAT_PNG;
  throw ImageError("unknown image format '" + name + "' (gray, bgr, rgb, jpeg, png)");
}

std::string format_name(int8_t format) {
  switch (format) {
    case image_t::FORMAT_GRAY8: return "GRAY8";
    case image_t::FORMAT_RGB8: return "RGB8";
    case image_t::FORMAT_BGR8: return "BGR8";
    case image_t::FORMAT_MJPEG: return "MJPEG";
    case image_t::FORMAT_PNG: return "PNG";
  }
  return "format " + std::to_string(format);
}

}  // namespace nudge::bus
