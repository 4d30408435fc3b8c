#pragma once
// Busy tables (issue 14): seeded scenes of 4-8 objects of every kind, some standing 3-5 cm apart
// or partly hiding each other, with photographs as the backdrop and the table top, shadows,
// transparent and reflective objects and sensor noise. A scene is plain data (scene.hpp); the
// same seed and pictures always give the same scene.
#include <cstdint>
#include <string>
#include <vector>

#include "nudge/sim/scene.hpp"

namespace nudge::sim {

struct ClutterOptions {
  int min_objects = 4, max_objects = 8;
  double min_gap = 0.03, max_gap = 0.05;  // m between the outlines of neighbours placed close
  double close_share = 0.6;               // share of objects placed close to an earlier one
  // The workspace ring on the table (from the arm's base, world origin) that objects stand in.
  double ring_inner = 0.18, ring_outer = 0.33;
  double max_abs_y = 0.22;                // m, keeps objects in both cameras' views
  std::vector<std::string> backdrops;     // PNG photographs for the wall (one is picked per scene)
  std::vector<std::string> tables;        // PNG photographs for the table top
};

// Throws std::invalid_argument naming the option if the options are unusable (no pictures, ...).
Scene clutter_scene(uint64_t seed, const ClutterOptions& options);

// The scene as a scene file (docs/sim.md) that load_scene() reads back to the same scene, with
// texture paths written relative to `directory` when they lie inside it.
std::string scene_yaml(const Scene& scene, const std::string& comment, const std::string& directory);

// Pictures kept for evaluating the detector on photographs (issue 14): never a scene texture.
bool is_reserved_picture(const std::string& path);

}  // namespace nudge::sim
