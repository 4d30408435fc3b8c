#include "nudge/sim/renderer.hpp"

#include "nudge/sim/world.hpp"

#include <GL/osmesa.h>
#include <mujoco/mujoco.h>

#include <cstring>
#include <string>

namespace nudge::sim {

struct Renderer::Impl {
  const mjModel* model = nullptr;
  OSMesaContext context = nullptr;
  std::vector<unsigned char> buffer;  // OSMesa's default framebuffer (RGBA)
  mjvScene scene;
  mjvOption option;
  mjrContext gl;
  std::vector<unsigned char> rgb;
  bool scene_made = false, gl_made = false;
  int buffer_width = 0, buffer_height = 0;

  void make_current() {
    if (!OSMesaMakeCurrent(context, buffer.data(), GL_UNSIGNED_BYTE, buffer_width, buffer_height))
      throw SimError("Renderer: OSMesaMakeCurrent failed");
  }

  // Renders camera `camera_id` into `rgb` (bottom row first, as OpenGL reads).
  void draw(mjData* data, int camera_id, int width, int height, const RenderSpec* spec,
            bool segment, int hidden_group, std::vector<float>* depth = nullptr) {
    if (camera_id < 0 || camera_id >= model->ncam)
      throw SimError("Renderer: no camera " + std::to_string(camera_id));
    make_current();
    mjvCamera camera;
    mjv_defaultCamera(&camera);
    camera.type = mjCAMERA_FIXED;
    camera.fixedcamid = camera_id;
    mjvOption opt = option;
    if (hidden_group >= 0 && hidden_group < mjNGROUP) opt.geomgroup[hidden_group] = 0;
    mjv_updateScene(model, data, &opt, nullptr, &camera, mjCAT_ALL, &scene);
    scene.flags[mjRND_SHADOW] = spec && spec->shadows ? 1 : 0;
    scene.flags[mjRND_REFLECTION] = spec && spec->reflections ? 1 : 0;
    scene.flags[mjRND_SKYBOX] = 0;
    scene.flags[mjRND_FOG] = 0;
    scene.flags[mjRND_HAZE] = 0;
    scene.flags[mjRND_SEGMENT] = segment ? 1 : 0;
    scene.flags[mjRND_IDCOLOR] = segment ? 1 : 0;
    mjr_setBuffer(mjFB_OFFSCREEN, &gl);
    const mjrRect viewport = {0, 0, width, height};
    mjr_render(viewport, &scene, &gl);
    rgb.resize(static_cast<size_t>(width) * height * 3);
    if (depth) depth->resize(static_cast<size_t>(width) * height);
    mjr_readPixels(rgb.data(), depth ? depth->data() : nullptr, viewport, &gl);
  }
};

Renderer::Renderer(const mjModel_* model, int width, int height)
    : impl_(std::make_unique<Impl>()), width_(width), height_(height) {
  if (!model) throw SimError("Renderer: no model");
  if (width <= 0 || height <= 0 || width > model->vis.global.offwidth ||
      height > model->vis.global.offheight)
    throw SimError("Renderer: image size " + std::to_string(width) + "x" + std::to_string(height) +
                   " exceeds the model's offscreen buffer " +
                   std::to_string(model->vis.global.offwidth) + "x" +
                   std::to_string(model->vis.global.offheight));
  impl_->model = model;
  impl_->context = OSMesaCreateContextExt(OSMESA_RGBA, 24, 8, 0, nullptr);
  if (!impl_->context) throw SimError("Renderer: OSMesaCreateContextExt failed");
  impl_->buffer.resize(static_cast<size_t>(width) * height * 4);
  impl_->buffer_width = width;
  impl_->buffer_height = height;
  try {
    impl_->make_current();
  } catch (...) {
    OSMesaDestroyContext(impl_->context);
    throw;
  }
  mjv_defaultOption(&impl_->option);
  mjv_defaultScene(&impl_->scene);
  mjv_makeScene(model, &impl_->scene, 2000);
  impl_->scene_made = true;
  mjr_defaultContext(&impl_->gl);
  mjr_makeContext(model, &impl_->gl, mjFONTSCALE_100);
  impl_->gl_made = true;
  if (!impl_->gl.offFBO) {
    mjr_freeContext(&impl_->gl);
    mjv_freeScene(&impl_->scene);
    OSMesaDestroyContext(impl_->context);
    throw SimError("Renderer: MuJoCo could not make an offscreen framebuffer with OSMesa");
  }
  mjr_setBuffer(mjFB_OFFSCREEN, &impl_->gl);
}

Renderer::~Renderer() {
  if (!impl_) return;
  if (impl_->context) OSMesaMakeCurrent(impl_->context, impl_->buffer.data(), GL_UNSIGNED_BYTE,
                                        width_, height_);
  if (impl_->gl_made) mjr_freeContext(&impl_->gl);
  if (impl_->scene_made) mjv_freeScene(&impl_->scene);
  if (impl_->context) {
    // Release the context before destroying it. (OSMesa itself keeps ~100 bytes per buffer it
    // has seen until exit; nothing here can free them.)
    OSMesaMakeCurrent(nullptr, nullptr, 0, 0, 0);
    OSMesaDestroyContext(impl_->context);
  }
}

cv::Size Renderer::checked(cv::Size size) const {
  if (size.empty()) return cv::Size(width_, height_);
  if (size.width > width_ || size.height > height_)
    throw SimError("Renderer: image size " + std::to_string(size.width) + "x" +
                   std::to_string(size.height) + " exceeds the renderer's " +
                   std::to_string(width_) + "x" + std::to_string(height_));
  return size;
}

cv::Mat Renderer::colour(mjData_* data, int camera_id, const RenderSpec& spec, int hidden_group,
                         cv::Size size) {
  size = checked(size);
  const int width = size.width, height = size.height;
  impl_->draw(data, camera_id, width, height, &spec, false, hidden_group);
  cv::Mat image(height, width, CV_8UC3);
  const size_t row = static_cast<size_t>(width) * 3;
  for (int y = 0; y < height; ++y) {
    const unsigned char* src = impl_->rgb.data() + (height - 1 - y) * row;
    unsigned char* dst = image.ptr<unsigned char>(y);
    for (int x = 0; x < width; ++x) {  // RGB -> BGR
      dst[3 * x + 0] = src[3 * x + 2];
      dst[3 * x + 1] = src[3 * x + 1];
      dst[3 * x + 2] = src[3 * x + 0];
    }
  }
  return image;
}

cv::Mat Renderer::labels(mjData_* data, int camera_id, const std::vector<unsigned char>& geom_label,
                         int hidden_group, cv::Size size, cv::Mat* depth) {
  size = checked(size);
  const int width = size.width, height = size.height;
  std::vector<float> buffer;
  impl_->draw(data, camera_id, width, height, nullptr, true, hidden_group, depth ? &buffer : nullptr);
  if (depth) {
    // OpenGL's depth buffer holds d in [0, 1] of MuJoCo's perspective projection; the distance
    // along the optical axis is near / (1 - d (1 - near / far)).
    const double extent = impl_->model->stat.extent;
    const double near = impl_->model->vis.map.znear * extent, far = impl_->model->vis.map.zfar * extent;
    depth->create(height, width, CV_32F);
    for (int y = 0; y < height; ++y) {
      const float* src = buffer.data() + static_cast<size_t>(height - 1 - y) * width;
      float* dst = depth->ptr<float>(y);
      for (int x = 0; x < width; ++x)
        dst[x] = static_cast<float>(near / (1.0 - src[x] * (1.0 - near / far)));
    }
  }
  // With mjRND_IDCOLOR each pixel holds the drawn geom's segid + 1 (little-endian RGB).
  const mjvScene& scene = impl_->scene;
  std::vector<unsigned char> segid_label;
  for (int i = 0; i < scene.ngeom; ++i) {
    const mjvGeom& g = scene.geoms[i];
    if (g.segid < 0 || g.objtype != mjOBJ_GEOM || g.objid < 0 ||
        g.objid >= static_cast<int>(geom_label.size()))
      continue;
    if (g.segid >= static_cast<int>(segid_label.size())) segid_label.resize(g.segid + 1, 0);
    segid_label[g.segid] = geom_label[g.objid];
  }
  cv::Mat out(height, width, CV_8U, cv::Scalar(0));
  const size_t row = static_cast<size_t>(width) * 3;
  const int n = static_cast<int>(segid_label.size());
  for (int y = 0; y < height; ++y) {
    const unsigned char* src = impl_->rgb.data() + (height - 1 - y) * row;
    unsigned char* dst = out.ptr<unsigned char>(y);
    for (int x = 0; x < width; ++x) {
      const int id = src[3 * x] | (src[3 * x + 1] << 8) | (src[3 * x + 2] << 16);
      if (id >= 1 && id <= n) dst[x] = segid_label[id - 1];
    }
  }
  return out;
}

}  // namespace nudge::sim
