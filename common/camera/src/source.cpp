#include "nudge/camera/source.hpp"

#include <glob.h>
#include <unistd.h>

#include <algorithm>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>
#include <stdexcept>

#include "nudge/camera/image_file.hpp"
#include "nudge/flags.hpp"
#include "nudge/log.hpp"

namespace nudge::camera {

std::vector<std::string> glob_files(const std::string& pattern) {
  glob_t g{};
  std::vector<std::string> files;
  if (::glob(pattern.c_str(), 0, nullptr, &g) == 0) {
    for (size_t i = 0; i < g.gl_pathc; ++i) files.emplace_back(g.gl_pathv[i]);
  }
  globfree(&g);
  std::sort(files.begin(), files.end());
  return files;
}

namespace {

class ImageFiles : public FrameSource {
 public:
  explicit ImageFiles(const std::string& pattern) : pattern_(pattern), files_(glob_files(pattern)) {
    if (files_.empty()) throw std::invalid_argument("images:" + pattern + " matches no files");
  }
  bool read(cv::Mat* frame) override {
    while (next_ < files_.size()) {
      const std::string& path = files_[next_++];
      try {
        *frame = read_image_file(path, cv::IMREAD_COLOR);
        return true;
      } catch (const ImageFileError& e) {
        log::error() << "skipped " << e.what();  // one bad file is not fatal
      }
    }
    return false;
  }
  bool rewind() override {
    next_ = 0;
    return true;
  }
  std::string describe() const override {
    return "images:" + pattern_ + " (" + std::to_string(files_.size()) + " files)";
  }

 private:
  std::string pattern_;
  std::vector<std::string> files_;
  size_t next_ = 0;
};

class Capture : public FrameSource {
 public:
  Capture(const std::string& spec, cv::VideoCapture cap, bool can_rewind)
      : spec_(spec), cap_(std::move(cap)), can_rewind_(can_rewind) {}
  bool read(cv::Mat* frame) override { return cap_.read(*frame) && !frame->empty(); }
  bool rewind() override { return can_rewind_ && cap_.set(cv::CAP_PROP_POS_FRAMES, 0); }
  std::string describe() const override { return spec_; }

 private:
  std::string spec_;
  cv::VideoCapture cap_;
  bool can_rewind_;
};

}  // namespace

std::unique_ptr<FrameSource> open_source(const std::string& spec) {
  const auto colon = spec.find(':');
  const std::string kind = spec.substr(0, colon);
  const std::string arg = colon == std::string::npos ? "" : spec.substr(colon + 1);
  if (kind == "images" && !arg.empty()) return std::make_unique<ImageFiles>(arg);
  if (kind == "video" && !arg.empty()) {
    if (::access(arg.c_str(), R_OK) != 0) throw std::invalid_argument("video:" + arg + " cannot be opened: no such file");
    cv::VideoCapture cap(arg);
    if (!cap.isOpened()) throw std::invalid_argument("video:" + arg + " cannot be opened");
    return std::make_unique<Capture>(spec, std::move(cap), true);
  }
  if (kind == "device" && !arg.empty()) {
    int index = 0;
    try {
      index = parse_int(arg, "device index in '" + spec + "'");
    } catch (const FlagError& e) {
      throw std::invalid_argument(e.what());
    }
    cv::VideoCapture cap(index);
    if (!cap.isOpened()) throw std::invalid_argument(spec + ": capture device cannot be opened");
    return std::make_unique<Capture>(spec, std::move(cap), false);
  }
  throw std::invalid_argument("unknown camera source '" + spec +
                              "' (expected images:GLOB, video:PATH or device:N)");
}

}  // namespace nudge::camera
