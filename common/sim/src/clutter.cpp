#include "nudge/sim/clutter.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <random>
#include <sstream>
#include <stdexcept>

#include "nudge/sim/objects.hpp"

namespace nudge::sim {

namespace {

using Rng = std::mt19937_64;

double uniform(Rng& rng, double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng); }
int uniform_int(Rng& rng, int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); }
bool chance(Rng& rng, double p) { return uniform(rng, 0, 1) < p; }

void check(const ClutterOptions& o) {
  auto require = [](bool ok, const std::string& what) {
    if (!ok) throw std::invalid_argument("clutter option " + what);
  };
  require(o.min_objects >= 1 && o.max_objects >= o.min_objects && o.max_objects <= 12,
          "min_objects/max_objects: need 1 <= min <= max <= 12");
  require(o.min_gap > 0 && o.max_gap >= o.min_gap, "min_gap/max_gap: need 0 < min <= max");
  require(o.close_share >= 0 && o.close_share <= 1, "close_share: must be in [0, 1]");
  require(o.ring_inner >= 0 && o.ring_outer > o.ring_inner + 0.05, "ring_inner/ring_outer: ring too narrow");
  require(o.max_abs_y > 0, "max_abs_y: must be positive");
  require(!o.backdrops.empty(), "backdrops: needs at least one PNG photograph");
  require(!o.tables.empty(), "tables: needs at least one PNG photograph");
  for (const auto& list : {o.backdrops, o.tables})
    for (const auto& file : list)
      require(!is_reserved_picture(file), "pictures: '" + file + "' is kept for evaluation on photographs");
}

// Every kind once (in a random order) before any repeats, so a family covers them all.
std::vector<std::string> pick_kinds(int count, Rng& rng) {
  std::vector<std::string> kinds = object_kinds();
  std::shuffle(kinds.begin(), kinds.end(), rng);
  std::vector<std::string> out;
  for (int i = 0; i < count; ++i)
    out.push_back(i < static_cast<int>(kinds.size()) ? kinds[i] : kinds[uniform_int(rng, 0, kinds.size() - 1)]);
  return out;
}

Eigen::Vector3d vivid_colour(Rng& rng) {
  Eigen::Vector3d c(uniform(rng, 0.05, 0.95), uniform(rng, 0.05, 0.95), uniform(rng, 0.05, 0.95));
  c[uniform_int(rng, 0, 2)] = uniform(rng, 0.75, 0.98);  // one strong channel: no muddy greys only
  return c;
}

Appearance object_look(const std::string& kind, Rng& rng) {
  Appearance a;
  a.colour = vivid_colour(rng);
  if (kind == "can") {  // reflective metal
    const double grey = uniform(rng, 0.6, 0.85);
    a.colour = Eigen::Vector3d(grey, grey, grey + 0.05 * uniform(rng, 0, 1));
    a.specular = 0.9;
    a.shininess = 0.8;
    a.reflectance = 0.3;
  } else if (kind == "bottle" && chance(rng, 0.6)) {  // clear or frosted plastic
    a.colour = Eigen::Vector3d(uniform(rng, 0.7, 0.9), uniform(rng, 0.8, 0.95), uniform(rng, 0.85, 1.0));
    a.opacity = uniform(rng, 0.3, 0.6);
    a.specular = 0.9;
    a.shininess = 0.9;
  } else if (kind != "marker" && chance(rng, 0.3)) {  // striped
    a.kind = Appearance::Kind::Checker;
    a.colour2 = vivid_colour(rng);
    a.repeat = uniform_int(rng, 3, 8);
  }
  return a;
}

struct Placed {
  Eigen::Vector2d xy;
  double radius;
};

bool fits(const Eigen::Vector2d& xy, double radius, const std::vector<Placed>& placed, const ClutterOptions& o) {
  const double range = xy.norm();
  if (range < o.ring_inner || range > o.ring_outer || std::fabs(xy.y()) > o.max_abs_y) return false;
  for (const Placed& p : placed)
    if ((xy - p.xy).norm() < p.radius + radius + 0.8 * o.min_gap) return false;
  return true;
}

Eigen::Vector2d anywhere(const ClutterOptions& o, Rng& rng) {
  const double range = uniform(rng, o.ring_inner, o.ring_outer);
  const double bearing = uniform(rng, -M_PI / 2, M_PI / 2);
  return {range * std::cos(bearing), range * std::sin(bearing)};
}

// Next to an earlier object, `gap` between the outlines; half of the time roughly along the
// cameras' line of sight (+x), so that one partly hides the other.
Eigen::Vector2d next_to(const Placed& other, double radius, const ClutterOptions& o, Rng& rng) {
  const double gap = uniform(rng, o.min_gap, o.max_gap);
  const double direction = chance(rng, 0.5) ? uniform(rng, -0.5, 0.5) + (chance(rng, 0.5) ? 0 : M_PI)
                                            : uniform(rng, -M_PI, M_PI);
  const double d = other.radius + radius + gap;
  return other.xy + d * Eigen::Vector2d(std::cos(direction), std::sin(direction));
}

std::string fmt(double v) {
  std::ostringstream s;
  s << std::setprecision(4) << v;
  return s.str();
}

std::string vec(const Eigen::Vector3d& v) { return "[" + fmt(v.x()) + ", " + fmt(v.y()) + ", " + fmt(v.z()) + "]"; }

std::string relative(const std::string& file, const std::string& directory) {
  if (directory.empty()) return file;
  const auto rel = std::filesystem::path(file).lexically_relative(std::filesystem::absolute(directory));
  return rel.empty() || rel.string().rfind("..", 0) == 0 ? file : rel.string();
}

std::string appearance_yaml(const Appearance& a, const std::string& directory) {
  std::string s = a.kind == Appearance::Kind::Image     ? "type: image, file: " + relative(a.file, directory)
                  : a.kind == Appearance::Kind::Checker ? "type: checker"
                                                        : "type: plain";
  s += ", colour: " + vec(a.colour);
  if (a.kind == Appearance::Kind::Checker) s += ", colour2: " + vec(a.colour2);
  if (a.kind != Appearance::Kind::Plain) s += ", repeat: " + fmt(a.repeat);
  s += ", specular: " + fmt(a.specular) + ", shininess: " + fmt(a.shininess);
  if (a.reflectance > 0) s += ", reflectance: " + fmt(a.reflectance);
  if (a.opacity < 1) s += ", opacity: " + fmt(a.opacity);
  return s;
}

}  // namespace

bool is_reserved_picture(const std::string& path) {
  const std::string stem = std::filesystem::path(path).stem().string();
  for (const char* reserved : {"building", "home", "graf1", "fruits", "box", "box_in_scene"})
    if (stem == reserved) return true;
  return false;
}

Scene clutter_scene(uint64_t seed, const ClutterOptions& o) {
  check(o);
  Rng rng(seed * 0x9E3779B97F4A7C15ULL + 14);
  Scene scene = default_scene();
  scene.source = "clutter seed " + std::to_string(seed);
  scene.seed = seed;
  scene.background.kind = Appearance::Kind::Image;
  scene.background.file = o.backdrops[uniform_int(rng, 0, o.backdrops.size() - 1)];
  scene.background.colour = Eigen::Vector3d::Ones();
  scene.background.repeat = uniform_int(rng, 1, 2);
  scene.table.kind = Appearance::Kind::Image;
  scene.table.file = o.tables[uniform_int(rng, 0, o.tables.size() - 1)];
  scene.table.colour = Eigen::Vector3d::Ones();
  scene.table.repeat = uniform_int(rng, 2, 4);
  scene.render.shadows = true;
  scene.render.reflections = true;
  scene.render.noise_sigma = 2.0;

  const int count = uniform_int(rng, o.min_objects, o.max_objects);
  std::vector<Placed> placed;
  for (const std::string& kind : pick_kinds(count, rng)) {
    const double radius = make_object(kind, 12).max_radius + (kind == "mug" ? 0.02 : 0.0);  // mug: its handle
    const bool close = !placed.empty() && chance(rng, o.close_share);
    Eigen::Vector2d xy;
    bool found = false;
    for (int attempt = 0; attempt < 400 && !found; ++attempt) {
      xy = close && attempt < 200 ? next_to(placed[uniform_int(rng, 0, placed.size() - 1)], radius, o, rng)
                                  : anywhere(o, rng);
      found = fits(xy, radius, placed, o);
    }
    if (!found) continue;  // the table is full: fewer objects
    placed.push_back({xy, radius});
    ObjectSpec obj;
    obj.kind = kind;
    obj.name = kind + std::to_string(placed.size() - 1);
    obj.position = xy;
    obj.yaw = uniform(rng, -M_PI, M_PI);
    obj.appearance = object_look(kind, rng);
    if (kind == "bottle" && chance(rng, 0.3)) obj.fill = uniform(rng, 0.3, 0.8);
    scene.objects.push_back(obj);
  }
  validate(scene);
  return scene;
}

std::string scene_yaml(const Scene& scene, const std::string& comment, const std::string& directory) {
  std::ostringstream y;
  y << "%YAML:1.0\n---\n";
  std::istringstream lines(comment);
  for (std::string line; std::getline(lines, line);) y << "# " << line << "\n";
  y << "seed: " << scene.seed << "\n";
  y << "table: { " << appearance_yaml(scene.table, directory) << " }\n";
  y << "background: { " << appearance_yaml(scene.background, directory) << " }\n";
  y << "render: { shadows: " << scene.render.shadows << ", reflections: " << scene.render.reflections
    << ", noise_sigma: " << fmt(scene.render.noise_sigma) << " }\n";
  if (scene.arm.present) {
    y << "arm: { present: 1, shoulder_height: " << fmt(scene.arm.shoulder_height) << ", joints_deg: [";
    for (size_t i = 0; i < scene.arm.joints.size(); ++i) y << (i ? ", " : "") << fmt(scene.arm.joints[i] * 180 / M_PI);
    y << "] }\n";
  }
  if (scene.physics.position_jitter > 0 || scene.physics.yaw_jitter > 0)
    y << "physics: { position_jitter: " << fmt(scene.physics.position_jitter)
      << ", yaw_jitter_deg: " << fmt(scene.physics.yaw_jitter * 180 / M_PI) << " }\n";
  y << "objects:\n";
  for (const ObjectSpec& o : scene.objects) {
    y << "  - { kind: " << o.kind << ", name: " << o.name << ", position: [" << fmt(o.position.x()) << ", "
      << fmt(o.position.y()) << "], yaw_deg: " << fmt(o.yaw * 180 / M_PI) << ",\n      "
      << appearance_yaml(o.appearance, directory);
    if (o.fill > 0) y << ", fill: " << fmt(o.fill);
    if (o.label.present())
      y << ",\n      label: { file: " << relative(o.label.file, directory) << ", bottom: " << fmt(o.label.bottom)
        << ", top: " << fmt(o.label.top) << " }";
    y << " }\n";
  }
  return y.str();
}

}  // namespace nudge::sim
