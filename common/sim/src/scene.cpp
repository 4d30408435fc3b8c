#include "nudge/sim/scene.hpp"

#include "nudge/robot/puma260.hpp"
#include "nudge/robot/safety.hpp"

#include "nudge/sim/mesh_file.hpp"
#include "nudge/sim/objects.hpp"
#include "nudge/sim/textures.hpp"

#include "nudge/yaml_file.hpp"

#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

namespace nudge::sim {

namespace {

constexpr double kDeg = M_PI / 180.0;

[[noreturn]] void fail(const std::string& source, const std::string& field, const std::string& what) {
  throw SceneError(source + ": " + field + ": " + what);
}

std::string join(const std::string& ctx, const std::string& key) {
  return ctx.empty() ? key : ctx + "." + key;
}

// Reads one map of the file, remembering which keys were used so that unknown ones (typos) are
// reported instead of silently ignored.
class MapReader {
 public:
  MapReader(const YAML::Node& node, std::string source, std::string ctx)
      : node_(node), source_(std::move(source)), ctx_(std::move(ctx)) {
    if (!node_.IsMap()) fail(source_, ctx_.empty() ? "(top level)" : ctx_, "expected a map");
  }

  bool has(const std::string& key) {
    used_.insert(key);
    return yaml_field(node_, key).has_value();
  }

  double number(const std::string& key, double def) {
    if (!has(key)) return def;
    const auto v = yaml_number(*yaml_field(node_, key));
    if (!v) fail(source_, join(ctx_, key), "expected a number");
    if (!std::isfinite(*v)) fail(source_, join(ctx_, key), "must be finite");
    return *v;
  }

  int integer(const std::string& key, int def) {
    if (!has(key)) return def;
    const auto v = yaml_int(*yaml_field(node_, key));
    if (!v) fail(source_, join(ctx_, key), "expected an integer");
    return *v;
  }

  bool boolean(const std::string& key, bool def) {
    if (!has(key)) return def;
    const YAML::Node n = *yaml_field(node_, key);
    if (const auto v = yaml_int(n)) {
      if (*v == 0 || *v == 1) return *v == 1;
    } else if (const auto s = yaml_text(n)) {
      if (*s == "true" || *s == "yes" || *s == "on") return true;
      if (*s == "false" || *s == "no" || *s == "off") return false;
    }
    fail(source_, join(ctx_, key), "expected a boolean (0/1, true/false)");
  }

  std::string string(const std::string& key, const std::string& def) {
    if (!has(key)) return def;
    const auto s = yaml_text(*yaml_field(node_, key));
    if (!s) fail(source_, join(ctx_, key), "expected a string");
    return *s;
  }

  std::vector<double> numbers(const std::string& key, size_t min_count, size_t max_count) {
    used_.insert(key);
    const auto n = yaml_field(node_, key);
    std::ostringstream expect;
    expect << "expected a sequence of " << min_count;
    if (max_count != min_count) expect << " to " << max_count;
    expect << " numbers";
    if (!n || !n->IsSequence() || n->size() < min_count || n->size() > max_count)
      fail(source_, join(ctx_, key), expect.str());
    std::vector<double> out;
    for (const YAML::Node& e : *n) {
      const auto v = yaml_number(e);
      if (!v) fail(source_, join(ctx_, key), expect.str());
      if (!std::isfinite(*v)) fail(source_, join(ctx_, key), "must be finite");
      out.push_back(*v);
    }
    return out;
  }

  Eigen::Vector3d vec3(const std::string& key, const Eigen::Vector3d& def) {
    if (!has(key)) return def;
    const auto v = numbers(key, 3, 3);
    return Eigen::Vector3d(v[0], v[1], v[2]);
  }

  // The value of a key has() found (a null node otherwise).
  YAML::Node node(const std::string& key) {
    used_.insert(key);
    return yaml_field(node_, key).value_or(YAML::Node());
  }

  // Throws for keys that were never asked for.
  void finish() const {
    for (const std::string& name : yaml_keys(node_)) {
      if (!used_.count(name)) fail(source_, join(ctx_, name), "unknown field");
    }
  }

  const std::string& ctx() const { return ctx_; }

 private:
  YAML::Node node_;
  std::string source_, ctx_;
  std::set<std::string> used_;
};

std::string directory_of(const std::string& path) {
  const auto slash = path.find_last_of('/');
  return slash == std::string::npos ? std::string(".") : path.substr(0, slash);
}

std::string resolve(const std::string& file, const std::string& dir) {
  if (file.empty() || file[0] == '/') return file;
  std::error_code ec;
  const auto full = std::filesystem::absolute(std::filesystem::path(dir) / file, ec);
  return ec ? dir + "/" + file : full.lexically_normal().string();
}

// Appearance keys may sit in their own map (table, background) or inline in an object's map.
void read_appearance(MapReader& r, Appearance& a, const std::string& source, const std::string& dir) {
  if (r.has("type")) {
    const std::string type = r.string("type", "plain");
    if (type == "plain")
      a.kind = Appearance::Kind::Plain;
    else if (type == "checker")
      a.kind = Appearance::Kind::Checker;
    else if (type == "image")
      a.kind = Appearance::Kind::Image;
    else
      fail(source, join(r.ctx(), "type"), "expected plain, checker or image, got '" + type + "'");
  }
  a.colour = r.vec3("colour", a.colour);
  a.colour2 = r.vec3("colour2", a.colour2);
  a.file = resolve(r.string("file", a.file), dir);
  a.repeat = r.number("repeat", a.repeat);
  a.specular = r.number("specular", a.specular);
  a.shininess = r.number("shininess", a.shininess);
  a.reflectance = r.number("reflectance", a.reflectance);
  a.opacity = r.number("opacity", a.opacity);
}

void check_picture(const std::string& file, const std::string& source, const std::string& field);

void check_appearance(const Appearance& a, const std::string& source, const std::string& ctx) {
  for (int i = 0; i < 3; ++i) {
    if (!(a.colour[i] >= 0 && a.colour[i] <= 1)) fail(source, join(ctx, "colour"), "components must be in [0, 1]");
    if (!(a.colour2[i] >= 0 && a.colour2[i] <= 1)) fail(source, join(ctx, "colour2"), "components must be in [0, 1]");
  }
  if (!(a.repeat > 0)) fail(source, join(ctx, "repeat"), "must be positive");
  if (!(a.specular >= 0 && a.specular <= 1)) fail(source, join(ctx, "specular"), "must be in [0, 1]");
  if (!(a.shininess >= 0 && a.shininess <= 1)) fail(source, join(ctx, "shininess"), "must be in [0, 1]");
  if (!(a.reflectance >= 0 && a.reflectance <= 1)) fail(source, join(ctx, "reflectance"), "must be in [0, 1]");
  if (!(a.opacity >= 0.05 && a.opacity <= 1)) fail(source, join(ctx, "opacity"), "must be in [0.05, 1]");
  if (a.kind == Appearance::Kind::Image) {
    if (a.file.empty()) fail(source, join(ctx, "file"), "type image needs a PNG file");
    if (a.file.find_first_of("\"<>&") != std::string::npos)
      fail(source, join(ctx, "file"), "'" + a.file + "': the characters \" < > & are not allowed");
    check_picture(a.file, source, join(ctx, "file"));
  }
}

void check_picture(const std::string& file, const std::string& source, const std::string& field) {
  std::ifstream in(file, std::ios::binary);
  if (!in) fail(source, field, "cannot read '" + file + "'");
  if (!is_image_file(file)) fail(source, field, "'" + file + "' is not a picture (PNG or JPEG)");
}

// Checks a label or a mesh and builds the object's model, or fails naming the field.
ObjectModel checked_model(const ObjectSpec& o, const std::string& src, const std::string& ctx) {
  if (o.kind == "mesh") {
    if (o.mesh.file.empty()) fail(src, join(ctx, "mesh.file"), "kind mesh needs a mesh file (.obj or .stl)");
    std::ifstream in(o.mesh.file, std::ios::binary);
    if (!in) fail(src, join(ctx, "mesh.file"), "cannot read '" + o.mesh.file + "'");
    if (!(o.mesh.scale > 0 && o.mesh.scale <= 100)) fail(src, join(ctx, "mesh.scale"), "must be in (0, 100]");
    if (!o.mesh.rotation.allFinite()) fail(src, join(ctx, "mesh.rotation_deg"), "must be finite");
    if (!o.mesh.texture.empty()) check_picture(o.mesh.texture, src, join(ctx, "mesh.texture"));
  } else {
    if (!o.mesh.file.empty() || !o.mesh.texture.empty())
      fail(src, join(ctx, "mesh"), "only objects of kind mesh take a mesh (this one is a " + o.kind + ")");
  }
  if (o.label.present()) {
    if (o.kind == "mesh" || o.kind == "marker")
      fail(src, join(ctx, "label"), "a " + o.kind + " takes no label (bottles, cans, cups and mugs do)");
    check_picture(o.label.file, src, join(ctx, "label.file"));
    if (!(o.label.specular >= 0 && o.label.specular <= 1)) fail(src, join(ctx, "label.specular"), "must be in [0, 1]");
    if (!(o.label.shininess >= 0 && o.label.shininess <= 1)) fail(src, join(ctx, "label.shininess"), "must be in [0, 1]");
  }
  try {
    return model_of(o, 8);
  } catch (const MeshFileError& e) {
    fail(src, join(ctx, "mesh.file"), std::string("the mesh does not load: ") + e.what());
  } catch (const std::invalid_argument& e) {
    fail(src, join(ctx, o.label.present() ? "label" : "mesh"), e.what());
  }
}

// `label: picture.jpg`, or `label: { file: picture.jpg, bottom: 0.03, top: 0.12, specular: .., shininess: .. }`.
void read_label(MapReader& r, LabelSpec& label, const std::string& source, const std::string& dir) {
  if (!r.has("label")) return;
  const YAML::Node node = r.node("label");
  const std::string ctx = join(r.ctx(), "label");
  if (const auto file = yaml_text(node)) {
    label.file = resolve(*file, dir);
    if (label.file.empty()) fail(source, ctx, "names no picture");
    return;
  }
  MapReader l(node, source, ctx);
  if (!l.has("file")) fail(source, join(ctx, "file"), "missing (a PNG or JPEG picture)");
  label.file = resolve(l.string("file", ""), dir);
  if (label.file.empty()) fail(source, join(ctx, "file"), "names no picture");
  label.bottom = l.number("bottom", label.bottom);
  label.top = l.number("top", label.top);
  label.specular = l.number("specular", label.specular);
  label.shininess = l.number("shininess", label.shininess);
  l.finish();
}

// `mesh: { file: duck.obj, texture: duck.png, scale: 0.01, rotation_deg: [90, 0, 0] }`.
void read_mesh(MapReader& r, MeshSpec& mesh, const std::string& source, const std::string& dir) {
  if (!r.has("mesh")) return;
  const std::string ctx = join(r.ctx(), "mesh");
  MapReader m(r.node("mesh"), source, ctx);
  if (!m.has("file")) fail(source, join(ctx, "file"), "missing (an .obj or .stl file)");
  mesh.file = resolve(m.string("file", ""), dir);
  mesh.texture = resolve(m.string("texture", ""), dir);
  mesh.scale = m.number("scale", mesh.scale);
  if (m.has("rotation_deg")) {
    const auto v = m.numbers("rotation_deg", 3, 3);
    mesh.rotation = Eigen::Vector3d(v[0], v[1], v[2]) * kDeg;
  }
  m.finish();
}

bool valid_name(const std::string& name) {
  if (name.empty()) return false;
  for (char c : name)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-')) return false;
  return true;
}

}  // namespace

ObjectModel model_of(const ObjectSpec& spec, int segments) {
  ObjectModel model = spec.kind == "mesh"
                          ? mesh_object(read_mesh_file(spec.mesh.file), spec.mesh.scale, spec.mesh.rotation)
                          : make_object(spec.kind, segments);
  if (spec.label.present()) {
    const auto [bottom, top] = label_band(spec);
    model.label = label_sleeve(model, bottom, top, segments);
  }
  return model;
}

std::pair<double, double> label_band(const ObjectSpec& spec) {
  auto band = default_label_band(spec.kind);
  if (spec.label.bottom >= 0) band.first = spec.label.bottom;
  if (spec.label.top >= 0) band.second = spec.label.top;
  return band;
}

Scene default_scene() {
  Scene scene;
  scene.table.colour = Eigen::Vector3d(0.72, 0.58, 0.42);
  scene.table.specular = 0.1;
  scene.table.shininess = 0.1;
  scene.table.reflectance = 0.1;
  scene.background.colour = Eigen::Vector3d(0.9, 0.9, 0.87);
  scene.background.specular = 0.0;
  scene.background.shininess = 0.0;
  return scene;
}

Scene load_scene(const std::string& path) {
  YAML::Node root;
  try {
    root = read_yaml_file(path, "scene");
  } catch (const std::runtime_error& e) {
    throw SceneError(e.what());
  }
  // A file of comments only (or nothing) is the default scene.
  if (root.IsNull()) root = YAML::Node(YAML::NodeType::Map);
  Scene scene = default_scene();
  scene.source = path;
  const std::string dir = directory_of(path);
  MapReader top(root, path, "");

  if (top.has("seed")) {
    const double seed = top.number("seed", 1);
    if (seed < 0 || seed != std::floor(seed)) fail(path, "seed", "expected a non-negative integer");
    scene.seed = static_cast<uint64_t>(seed);
  }
  if (top.has("table")) {
    MapReader r(top.node("table"), path, "table");
    read_appearance(r, scene.table, path, dir);
    r.finish();
  }
  if (top.has("background")) {
    MapReader r(top.node("background"), path, "background");
    read_appearance(r, scene.background, path, dir);
    r.finish();
  }
  if (top.has("cameras")) {
    MapReader r(top.node("cameras"), path, "cameras");
    RigSpec& rig = scene.rig;
    rig.target = r.vec3("target", rig.target);
    rig.distance = r.number("distance", rig.distance);
    rig.elevation = r.number("elevation_deg", rig.elevation / kDeg) * kDeg;
    rig.azimuth = r.number("azimuth_deg", rig.azimuth / kDeg) * kDeg;
    rig.baseline = r.number("baseline", rig.baseline);
    rig.vergence = r.number("vergence_deg", rig.vergence / kDeg) * kDeg;
    rig.width = r.integer("width", rig.width);
    rig.height = r.integer("height", rig.height);
    rig.fovy = r.number("fovy_deg", rig.fovy / kDeg) * kDeg;
    if (r.has("distortion")) {
      const auto d = r.numbers("distortion", 5, 5);
      for (int i = 0; i < 5; ++i) rig.distortion[i] = d[i];
    }
    r.finish();
  }
  if (top.has("render")) {
    MapReader r(top.node("render"), path, "render");
    RenderSpec& render = scene.render;
    render.shadows = r.boolean("shadows", render.shadows);
    render.reflections = r.boolean("reflections", render.reflections);
    render.antialias = r.boolean("antialias", render.antialias);
    render.noise_sigma = r.number("noise_sigma", render.noise_sigma);
    render.snapshot_scale = r.integer("snapshot_scale", render.snapshot_scale);
    render.ambient = r.number("ambient", render.ambient);
    render.light = r.number("light", render.light);
    r.finish();
  }
  if (top.has("arm")) {
    MapReader r(top.node("arm"), path, "arm");
    ArmSpec& arm = scene.arm;
    arm.present = r.boolean("present", true);
    arm.shoulder_height = r.number("shoulder_height", arm.shoulder_height);
    if (r.has("joints_deg")) {
      const auto j = r.numbers("joints_deg", 6, 6);
      for (int i = 0; i < 6; ++i) arm.joints[i] = j[i] * kDeg;
    }
    r.finish();
  }
  if (top.has("physics")) {
    MapReader r(top.node("physics"), path, "physics");
    PhysicsSpec& physics = scene.physics;
    physics.timestep = r.number("timestep", physics.timestep);
    physics.settle_time = r.number("settle_time", physics.settle_time);
    physics.position_jitter = r.number("position_jitter", physics.position_jitter);
    physics.yaw_jitter = r.number("yaw_jitter_deg", physics.yaw_jitter / kDeg) * kDeg;
    physics.table_friction = r.number("table_friction", physics.table_friction);
    physics.elliptic_cone = r.boolean("elliptic_cone", physics.elliptic_cone);
    physics.impratio = r.number("impratio", physics.impratio);
    physics.noslip_iterations = r.integer("noslip_iterations", physics.noslip_iterations);
    r.finish();
  }
  if (top.has("objects")) {
    const YAML::Node objects = top.node("objects");
    if (!objects.IsSequence()) fail(path, "objects", "expected a sequence of object maps");
    size_t i = 0;
    for (const YAML::Node& object : objects) {
      const std::string ctx = "objects[" + std::to_string(i++) + "]";
      MapReader r(object, path, ctx);
      ObjectSpec obj;
      if (!r.has("kind")) fail(path, join(ctx, "kind"), "missing (one of cup, mug, bottle, can, marker, mesh)");
      obj.kind = r.string("kind", "");
      obj.name = r.string("name", "");
      if (!r.has("position")) fail(path, join(ctx, "position"), "missing ([x, y] in metres)");
      const auto p = r.numbers("position", 2, 2);
      obj.position = Eigen::Vector2d(p[0], p[1]);
      obj.yaw = r.number("yaw_deg", 0.0) * kDeg;
      obj.mass = r.number("mass", 0.0);
      obj.friction = r.number("friction", 0.0);
      obj.fill = r.number("fill", 0.0);
      read_label(r, obj.label, path, dir);
      read_mesh(r, obj.mesh, path, dir);
      read_appearance(r, obj.appearance, path, dir);
      r.finish();
      scene.objects.push_back(obj);
    }
  }
  top.finish();
  validate(scene);
  return scene;
}

void validate(const Scene& scene) {
  const std::string& src = scene.source;
  check_appearance(scene.table, src, "table");
  check_appearance(scene.background, src, "background");
  if (scene.objects.size() > 254) fail(src, "objects", "at most 254 objects (mask labels are 8-bit)");
  std::set<std::string> names;
  std::vector<double> footprint;  // object index -> widest radius
  for (size_t i = 0; i < scene.objects.size(); ++i) {
    const ObjectSpec& o = scene.objects[i];
    const std::string ctx = "objects[" + std::to_string(i) + "]";
    if (!is_object_kind(o.kind) && o.kind != "mesh") {
      std::string known;
      for (const auto& k : object_kinds()) known += (known.empty() ? "" : ", ") + k;
      fail(src, join(ctx, "kind"), "unknown kind '" + o.kind + "' (known: " + known + ", mesh)");
    }
    if (!o.name.empty()) {
      if (!valid_name(o.name)) fail(src, join(ctx, "name"), "'" + o.name + "': use letters, digits, _ and -");
      if (!names.insert(o.name).second) fail(src, join(ctx, "name"), "'" + o.name + "' is used twice");
    }
    if (!o.position.allFinite() || o.position.x() <= kTableXMin + 0.05 ||
        o.position.x() >= kTableXMax - 0.05 || std::fabs(o.position.y()) >= kTableHalfY - 0.05)
    {
      std::ostringstream what;
      what << "must be on the table (x in (" << kTableXMin + 0.05 << ", " << kTableXMax - 0.05
           << "), |y| < " << kTableHalfY - 0.05 << " m)";
      fail(src, join(ctx, "position"), what.str());
    }
    if (!std::isfinite(o.yaw)) fail(src, join(ctx, "yaw"), "must be finite");
    if (!(o.mass >= 0 && o.mass < 20)) fail(src, join(ctx, "mass"), "must be in [0, 20) kg (0 = default)");
    if (!(o.friction >= 0 && o.friction < 5)) fail(src, join(ctx, "friction"), "must be in [0, 5) (0 = default)");
    if (!(o.fill >= 0 && o.fill <= 1)) fail(src, join(ctx, "fill"), "must be in [0, 1]");
    check_appearance(o.appearance, src, ctx);
    footprint.push_back(checked_model(o, src, ctx).max_radius);
  }
  // Objects must not start inside each other (footprints: widest radius; a mug's handle may
  // still touch a neighbour).
  for (size_t i = 0; i < scene.objects.size(); ++i)
    for (size_t j = 0; j < i; ++j) {
      const ObjectSpec& a = scene.objects[i];
      const ObjectSpec& b = scene.objects[j];
      const double gap = (a.position - b.position).norm() - footprint[i] - footprint[j];
      if (gap < 0)
        fail(src, "objects[" + std::to_string(i) + "].position",
             "overlaps objects[" + std::to_string(j) + "] by " +
                 std::to_string(static_cast<int>(std::ceil(-gap * 1000))) + " mm");
    }
  const RigSpec& rig = scene.rig;
  if (!rig.target.allFinite()) fail(src, "cameras.target", "must be finite");
  if (!(rig.distance > 0.05 && rig.distance < 10)) fail(src, "cameras.distance", "must be in (0.05, 10) m");
  if (!(rig.elevation > -M_PI / 2 && rig.elevation < M_PI / 2)) fail(src, "cameras.elevation_deg", "must be in (-90, 90)");
  if (!std::isfinite(rig.azimuth)) fail(src, "cameras.azimuth_deg", "must be finite");
  if (!(rig.baseline > 0 && rig.baseline < 2)) fail(src, "cameras.baseline", "must be in (0, 2) m");
  if (!(rig.vergence >= 0 && rig.vergence < M_PI / 2)) fail(src, "cameras.vergence_deg", "must be in [0, 90)");
  if (rig.width < 16 || rig.width > 4096) fail(src, "cameras.width", "must be in [16, 4096]");
  if (rig.height < 16 || rig.height > 4096) fail(src, "cameras.height", "must be in [16, 4096]");
  if (!(rig.fovy > 1 * kDeg && rig.fovy < 170 * kDeg)) fail(src, "cameras.fovy_deg", "must be in (1, 170)");
  for (double d : rig.distortion)
    if (!(std::fabs(d) <= 2)) fail(src, "cameras.distortion", "coefficients must be in [-2, 2]");
  const RenderSpec& r = scene.render;
  if (!(r.noise_sigma >= 0 && r.noise_sigma < 100)) fail(src, "render.noise_sigma", "must be in [0, 100)");
  if (r.snapshot_scale < 1 || r.snapshot_scale > 4) fail(src, "render.snapshot_scale", "must be 1, 2, 3 or 4");
  if (!(r.ambient >= 0 && r.ambient <= 1)) fail(src, "render.ambient", "must be in [0, 1]");
  if (!(r.light >= 0 && r.light <= 1)) fail(src, "render.light", "must be in [0, 1]");
  const ArmSpec& arm = scene.arm;
  if (!(arm.shoulder_height >= 0.1 && arm.shoulder_height <= 1.0)) fail(src, "arm.shoulder_height", "must be in [0.1, 1] m");
  if (arm.present) {
    for (size_t i = 0; i < scene.objects.size(); ++i) {
      const ObjectSpec& o = scene.objects[i];
      if (o.position.norm() < robot::SafetyConfig{}.pedestal_radius + footprint[i])
        fail(src, "objects[" + std::to_string(i) + "].position", "overlaps the arm's pedestal at the origin");
    }
  }
  const robot::ArmModel puma = robot::puma260();
  for (int j = 0; j < 6; ++j) {
    if (!(arm.joints[j] >= puma.limits.lower[j] && arm.joints[j] <= puma.limits.upper[j]))
      fail(src, "arm.joints_deg", "joint " + std::to_string(j + 1) + " is outside its limits (docs/robot.md)");
  }
  const PhysicsSpec& p = scene.physics;
  if (!(p.timestep > 0 && p.timestep <= 0.01)) fail(src, "physics.timestep", "must be in (0, 0.01] s");
  if (!(p.settle_time >= 0 && p.settle_time <= 10)) fail(src, "physics.settle_time", "must be in [0, 10] s");
  if (!(p.position_jitter >= 0 && p.position_jitter < 0.1)) fail(src, "physics.position_jitter", "must be in [0, 0.1) m");
  if (!(p.yaw_jitter >= 0 && p.yaw_jitter <= M_PI)) fail(src, "physics.yaw_jitter_deg", "must be in [0, 180]");
  if (!(p.table_friction > 0 && p.table_friction < 5)) fail(src, "physics.table_friction", "must be in (0, 5)");
  if (!(p.impratio >= 1 && p.impratio <= 1000)) fail(src, "physics.impratio", "must be in [1, 1000]");
  if (p.noslip_iterations < 0 || p.noslip_iterations > 1000) fail(src, "physics.noslip_iterations", "must be in [0, 1000]");
}

}  // namespace nudge::sim
