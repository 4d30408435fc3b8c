#pragma once
// What the simulated world's tests (tests/unit/sim/*_test.cpp, one binary sim_test) share:
// shipped scene paths, scene files written on the fly, one-object scenes.
#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <unistd.h>

#include "nudge/sim/camera.hpp"
#include "nudge/sim/mjcf.hpp"
#include "nudge/sim/objects.hpp"
#include "nudge/sim/scene.hpp"
#include "nudge/sim/world.hpp"

namespace nudge::sim::test {

constexpr double kDeg = M_PI / 180.0;

inline std::string scene_path(const std::string& name) {
  return std::string(NUDGE_SOURCE_DIR) + "/common/sim/scenes/" + name;
}

// Writes `text` to a fresh temporary .yaml file and returns its path.
inline std::string temp_scene(const std::string& text) {
  static int counter = 0;
  const std::string path = "/tmp/nudge_sim_test_" + std::to_string(::getpid()) + "_" +
                           std::to_string(counter++) + ".yaml";
  std::ofstream(path) << text;
  return path;
}

// The message of the SceneError thrown when loading `text`, or "" if none is thrown.
inline std::string load_error(const std::string& text, std::string* path_out = nullptr) {
  const std::string path = temp_scene(text);
  if (path_out) *path_out = path;
  std::string message;
  try {
    load_scene(path);
  } catch (const SceneError& e) {
    message = e.what();
  }
  std::remove(path.c_str());
  return message;
}

inline Scene one_object(const std::string& kind, double x = 0.25, double y = 0.0) {
  Scene scene = default_scene();
  ObjectSpec o;
  o.kind = kind;
  o.position = Eigen::Vector2d(x, y);
  o.appearance.colour = Eigen::Vector3d(0.95, 0.95, 0.95);
  scene.objects.push_back(o);
  return scene;
}

inline double radius_at(const std::string& kind, double z) { return make_object(kind).radius_at(z); }

}  // namespace nudge::sim::test
