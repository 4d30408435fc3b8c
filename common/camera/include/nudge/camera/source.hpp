#pragma once
// Where camera frames come from: image files, a video file, a capture device. The simulated
// world's renderer plugs in as another FrameSource ("sim").
#include <opencv2/core.hpp>

#include <memory>
#include <string>
#include <vector>

namespace nudge::camera {

class FrameSource {
 public:
  virtual ~FrameSource() = default;
  // Next frame, or false at the end of the source. Throws std::runtime_error on a read failure
  // that names the file or device.
  virtual bool read(cv::Mat* frame) = 0;
  // Back to the first frame; false if the source cannot rewind (a live device).
  virtual bool rewind() = 0;
  virtual std::string describe() const = 0;
};

// "images:GLOB", "video:PATH", "device:N". Throws std::invalid_argument naming the spec when it
// is malformed, names no files, or cannot be opened.
std::unique_ptr<FrameSource> open_source(const std::string& spec);

// Files matching a glob pattern, sorted by name (what images:GLOB reads).
std::vector<std::string> glob_files(const std::string& pattern);

}  // namespace nudge::camera
