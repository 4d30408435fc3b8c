#pragma once
// Scene description of the simulated world: what stands on the table, what the table and the
// backdrop look like, where the stereo cameras are, and how physics and rendering are set up.
// A scene is plain data: build one in code, or load it from a YAML file (OpenCV's style)
// (format in docs/sim.md). Units: metres, radians in code, degrees in files (`*_deg` fields).
//
// World frame: origin on the PUMA's base axis at table-top height, z up (table top is z = 0),
// x from the arm base towards the workspace and the cameras, y to the left seen from the arm.
#include <Eigen/Core>

#include "nudge/robot/workspace.hpp"
#include "nudge/sim/objects.hpp"

#include <array>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace nudge::sim {

// The table top drawn (world frame, metres); its plane z = 0 is infinite for collisions. The
// backdrop wall stands along its far edge x = kTableXMin.
constexpr double kTableXMin = -0.6, kTableXMax = 1.1, kTableHalfY = 1.0;

// Any error in a scene: the message names the file (or "scene") and the offending field.
class SceneError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The look of a surface (table top, backdrop, or an object).
struct Appearance {
  enum class Kind { Plain, Checker, Image };
  Kind kind = Kind::Plain;
  Eigen::Vector3d colour{0.8, 0.8, 0.8};   // RGB in [0, 1]
  Eigen::Vector3d colour2{0.3, 0.3, 0.3};  // second colour of a checker
  std::string file;                        // PNG or JPEG for Kind::Image (absolute, or relative to the scene file)
  double repeat = 4.0;                     // texture repetitions across the surface
  double specular = 0.3;
  double shininess = 0.3;
  double reflectance = 0.0;                // only drawn when Render::reflections is on
  double opacity = 1.0;                    // 1 = opaque; less: transparent (glass, clear plastic)
};

// A picture wrapped once round a body of revolution (bottle, can, cup, mug) over a band of its
// side, like a drink bottle's label. Drawn only: it changes neither collisions nor mass.
struct LabelSpec {
  std::string file;      // PNG or JPEG (anything OpenCV reads); empty = no label
  double bottom = -1.0;  // m above the base; < 0: the kind's default band (default_label_band())
  double top = -1.0;
  double specular = 0.3, shininess = 0.3;
  bool present() const { return !file.empty(); }
};

// An object of kind "mesh": the triangles of a user's OBJ or STL file.
struct MeshSpec {
  std::string file;                                 // .obj or .stl (absolute, or relative to the scene file)
  std::string texture;                              // optional picture mapped by the OBJ's texture coordinates
  double scale = 1.0;                               // file units to metres (e.g. 0.001 for millimetres)
  Eigen::Vector3d rotation = Eigen::Vector3d::Zero();  // x-y-z Euler angles, rad (e.g. a Y-up file: x = 90 deg)
};

struct ObjectSpec {
  std::string name;                // unique; defaults to "<kind><index>"
  std::string kind;                // a kind of the object library: cup, mug, bottle, can, marker; or mesh
  Eigen::Vector2d position{0.25, 0.0};  // of the base centre on the table, world x y
  double yaw = 0.0;                // about the world z axis (turns a mug's handle)
  Appearance appearance;
  double mass = 0.0;               // kg; 0 = the library's default for the kind
  double friction = 0.0;           // sliding friction; 0 = the library's default
  double fill = 0.0;               // fraction of the liquid space filled with water (rigid: no sloshing)
  LabelSpec label;                 // bodies of revolution only
  MeshSpec mesh;                   // kind "mesh" only
};

// A verged stereo pair (thesis ch. 4.3). The rig's centre looks at `target` from `distance`,
// `elevation` above the horizontal (look-down angle), from the direction `azimuth` (0: from +x).
// The two cameras sit `baseline` apart on the rig's horizontal axis and are each turned inwards by
// vergence / 2 (their optical axes meet at baseline / 2 / tan(vergence / 2) in front of the rig).
struct RigSpec {
  Eigen::Vector3d target{0.25, 0.0, 0.06};
  double distance = 0.7;
  double elevation = 30.0 * M_PI / 180.0;
  double azimuth = 0.0;
  double baseline = 0.25;
  double vergence = 15.0 * M_PI / 180.0;
  int width = 640;
  int height = 480;
  double fovy = 45.0 * M_PI / 180.0;  // vertical field of view
  // Lens distortion of both cameras, OpenCV's model and order (k1, k2, p1, p2, k3) on normalised
  // coordinates; all zero = an ideal pinhole. Rendered by warping a larger pinhole image.
  std::array<double, 5> distortion{{0, 0, 0, 0, 0}};
};

struct RenderSpec {
  bool shadows = false;
  bool reflections = false;
  bool antialias = false;        // 4x multisampling (slower; masks get mixed ids on edges)
  double noise_sigma = 0.0;      // Gaussian pixel noise (grey levels), seeded by the scene seed
  int snapshot_scale = 2;        // high-resolution stills (thesis ch. 6: 1280x960) = scale x rig size
  double ambient = 0.35;         // headlight ambient
  double light = 0.55;           // diffuse intensity of the overhead lights
};

struct PhysicsSpec {
  double timestep = 0.002;       // s, fixed
  double settle_time = 0.5;      // s simulated when the world is built, so objects start at rest
  double position_jitter = 0.0;  // m, std of a seeded random offset added to each object position
  double yaw_jitter = 0.0;       // rad, likewise for the yaw
  double table_friction = 0.5;
  // MuJoCo's contacts are soft: friction lets objects creep under any sideways force. An
  // elliptic friction cone with a high impratio, plus the no-slip solver, make friction hard
  // enough that a pushed object tips when pushed high instead of sliding.
  bool elliptic_cone = true;
  double impratio = 10.0;
  int noslip_iterations = 0;
};

// The PUMA 260 arm (thesis App. B, Table B.1) standing on the table with its base axis on the
// world z axis: six hinge joints with the robot library's limits, position actuators, links that
// push objects aside. Its DH frame 0 is the world frame lifted to the shoulder.
struct ArmSpec {
  bool present = false;
  double shoulder_height = robot::Workspace{}.shoulder_height;  // the shoulder above the table top, m
  std::array<double, 6> joints{{0, M_PI / 2, -M_PI / 2, 0, 0, 0}};  // start pose, rad: straight up
};

struct Scene {
  std::string source = "scene";  // file the scene came from (for messages)
  uint64_t seed = 1;
  Appearance table;              // table top
  Appearance background;         // backdrop wall behind the table
  std::vector<ObjectSpec> objects;
  RigSpec rig;
  RenderSpec render;
  PhysicsSpec physics;
  ArmSpec arm;
};

// The model of a scene object: the object library's kind (make_object()), or a mesh file's
// triangles (kind "mesh"), with its label's sleeve if it has one. Throws std::invalid_argument or
// MeshFileError (mesh_file.hpp) with the reason; validate() turns those into SceneErrors naming
// the field.
ObjectModel model_of(const ObjectSpec& spec, int segments = 48);

// The heights above the base [bottom, top] a label covers: the spec's, or its kind's default band
// where the spec leaves them negative (default_label_band()). Throws std::invalid_argument for a
// kind with no place for a label.
std::pair<double, double> label_band(const ObjectSpec& spec);

// Defaults for the table and backdrop: light wood-coloured table, plain off-white wall.
Scene default_scene();

// Loads a YAML (or JSON) scene file, parsed by yaml-cpp (nudge/yaml_file.hpp). Missing fields take default_scene()'s
// values. Throws SceneError naming the file and the field ("scenes/x.yaml: objects[1].kind: ...").
Scene load_scene(const std::string& path);

// Checks a scene built in code (kinds exist, names unique, numbers finite and in range, texture
// files readable). Throws SceneError naming scene.source and the field. load_scene() calls it.
void validate(const Scene& scene);

}  // namespace nudge::sim
