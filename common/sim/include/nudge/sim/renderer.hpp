#pragma once
// Headless offscreen rendering of a MuJoCo model through OSMesa (software OpenGL): one OSMesa
// context per Renderer, made current for each call, so several Renderers may coexist in one
// thread. Used by World; exposed for tools that hold their own mjModel / mjData.
#include "nudge/sim/scene.hpp"

#include <opencv2/core.hpp>

#include <memory>
#include <vector>

struct mjModel_;
struct mjData_;

namespace nudge::sim {

class Renderer {
 public:
  // The largest image size; it must not exceed the model's <visual><global offwidth offheight>.
  // Throws SimError (world.hpp) when no context can be made.
  Renderer(const mjModel_* model, int width, int height);
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  int width() const { return width_; }
  int height() const { return height_; }

  // Colour image (BGR, top row first) of the model's fixed camera `camera_id`, `size` pixels
  // (empty: the largest size). `hidden_group`: a geom group not to draw (-1: none hidden).
  cv::Mat colour(mjData_* data, int camera_id, const RenderSpec& spec, int hidden_group = -1,
                 cv::Size size = cv::Size());
  // Segmentation: each pixel gets geom_label[id of the model geom seen there] (0 for none).
  // `depth` (if not null): CV_32F, each pixel's distance along the optical axis, metres.
  cv::Mat labels(mjData_* data, int camera_id, const std::vector<unsigned char>& geom_label,
                 int hidden_group = -1, cv::Size size = cv::Size(), cv::Mat* depth = nullptr);

 private:
  cv::Size checked(cv::Size size) const;
  struct Impl;
  std::unique_ptr<Impl> impl_;
  int width_, height_;
};

}  // namespace nudge::sim
