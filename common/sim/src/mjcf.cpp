#include "nudge/sim/mjcf.hpp"

#include "nudge/sim/camera.hpp"
#include "nudge/sim/objects.hpp"
#include "nudge/sim/textures.hpp"

#include "nudge/robot/puma260.hpp"
#include "nudge/robot/safety.hpp"

#include <algorithm>
#include <cmath>
#include <locale>
#include <sstream>

namespace nudge::sim {

namespace {

class Xml {
 public:
  Xml() {
    out_.imbue(std::locale::classic());
    out_.precision(9);
  }
  template <typename T>
  Xml& operator<<(const T& v) {
    out_ << v;
    return *this;
  }
  std::string str() const { return out_.str(); }

 private:
  std::ostringstream out_;
};

std::string vec(const Eigen::Vector3d& v) {
  std::ostringstream s;
  s.imbue(std::locale::classic());
  s.precision(9);
  s << v.x() << ' ' << v.y() << ' ' << v.z();
  return s.str();
}


// The PNG MuJoCo loads for a picture the scene names in `field`.
std::string texture_file(const std::string& file, const std::string& source, const std::string& field) {
  try {
    return png_texture(file);
  } catch (const TextureError& e) {
    throw SceneError(source + ": " + field + ": " + e.what());
  }
}

// A picture texture + material pair (labels, a mesh's own texture: its texture coordinates as they are).
void add_picture_material(Xml& assets, const std::string& name, const std::string& png, double specular,
                          double shininess, double opacity) {
  assets << "    <texture name=\"" << name << "_tex\" type=\"2d\" file=\"" << png << "\"/>\n"
         << "    <material name=\"" << name << "\" texture=\"" << name << "_tex\" rgba=\"1 1 1 " << opacity
         << "\" specular=\"" << specular << "\" shininess=\"" << shininess << "\"/>\n";
}

// A texture + material pair for an appearance. Returns the material name. `field`: where the
// scene sets it (for errors).
std::string add_material(Xml& assets, const std::string& name, const Appearance& a, bool mesh,
                         const std::string& source, const std::string& field) {
  const std::string tex = name + "_tex";
  bool textured = false;
  if (a.kind == Appearance::Kind::Checker) {
    assets << "    <texture name=\"" << tex << "\" type=\"2d\""
           << " builtin=\"checker\" rgb1=\"" << vec(a.colour) << "\" rgb2=\"" << vec(a.colour2)
           << "\" width=\"256\" height=\"256\"/>\n";
    textured = true;
  } else if (a.kind == Appearance::Kind::Image) {
    assets << "    <texture name=\"" << tex << "\" type=\"2d\" file=\""
           << texture_file(a.file, source, field + ".file") << "\"/>\n";
    textured = true;
  }
  assets << "    <material name=\"" << name << "\"";
  if (textured) {
    assets << " texture=\"" << tex << "\" rgba=\"1 1 1 " << a.opacity << "\"";
    if (!mesh) assets << " texrepeat=\"" << a.repeat << ' ' << a.repeat << "\" texuniform=\"false\"";
  } else {
    assets << " rgba=\"" << vec(a.colour) << ' ' << a.opacity << "\"";
  }
  assets << " specular=\"" << a.specular << "\" shininess=\"" << a.shininess
         << "\" reflectance=\"" << a.reflectance << "\"/>\n";
  return name;
}

// `repeat`: texture repetitions around the object (MuJoCo's texrepeat does not apply to mesh
// texture coordinates, so they are scaled here).
void add_mesh(Xml& assets, const std::string& name, const Mesh& mesh, double repeat) {
  assets << "    <mesh name=\"" << name << "\" vertex=\"";
  for (const auto& v : mesh.vertices) assets << v.x() << ' ' << v.y() << ' ' << v.z() << ' ';
  assets << "\" texcoord=\"";
  for (const auto& t : mesh.texcoords) assets << repeat * t.x() << ' ' << repeat * t.y() << ' ';
  assets << "\" face=\"";
  for (const auto& f : mesh.faces) assets << f[0] << ' ' << f[1] << ' ' << f[2] << ' ';
  assets << "\"/>\n";
}

}  // namespace

const Eigen::Vector3d& pusher_park_position() {
  static const Eigen::Vector3d park(-1.0, 0.0, 0.5);  // behind the backdrop
  return park;
}

const Eigen::Vector3d& pusher_pad_half_size() {
  static const Eigen::Vector3d half(0.01, 0.04, 0.015);
  return half;
}

const GripperGeometry& gripper_geometry() {
  static const GripperGeometry g;
  return g;
}

// A centred vertical cylinder of radius r touches a face through the apex (0, a) whose normal
// makes the angle alpha with the closing axis when r = a cos(alpha).
double GripperGeometry::apex_for_opening(double opening) const {
  return 0.5 * opening / std::cos(groove_half_angle);
}

double GripperGeometry::opening_for_apex(double apex) const {
  return 2.0 * apex * std::cos(groove_half_angle);
}

namespace {

// One finger: a body on a slide joint along `side` * tool y, its groove's apex at the body
// origin, two rows of two faces opening towards the tool point.
void add_finger(Xml& x, const std::string& name, int side) {
  const GripperGeometry& g = gripper_geometry();
  const double a = g.groove_half_angle, ca = std::cos(a), sa = std::sin(a);
  const double range = g.apex_for_opening(g.max_opening + 0.01);
  x << "      <body name=\"" << name << "\">\n"
    << "        <joint name=\"" << name << "_slide\" type=\"slide\" axis=\"0 " << side
    << " 0\" limited=\"true\" range=\"0 " << range << "\" damping=\"" << g.damping << "\"/>\n"
    << "        <inertial pos=\"0 0 0\" mass=\"" << g.finger_mass << "\" diaginertia=\"2e-5 2e-5 2e-5\"/>\n";
  int k = 0;
  for (int row = -1; row <= 1; row += 2) {
    for (int end = -1; end <= 1; end += 2) {
      // Along the face from the apex (towards the tool point and to one side), and its outward normal.
      const Eigen::Vector3d along(end * ca, -side * sa, 0), normal(end * sa, side * ca, 0);
      const Eigen::Vector3d centre =
          g.face_half_length * along + g.face_half_thickness * normal + Eigen::Vector3d(0, 0, row * g.row_offset);
      x << "        <geom name=\"" << name << "_" << k++ << "\" type=\"box\" size=\"" << g.face_half_length
        << ' ' << g.face_half_thickness << ' ' << g.face_half_height << "\" pos=\"" << vec(centre)
        << "\" euler=\"0 0 " << std::atan2(along.y(), along.x()) << "\" rgba=\"0.2 0.2 0.22 1\" group=\"2\""
        << " contype=\"2\" conaffinity=\"0\" condim=\"3\" friction=\"" << g.friction
        << " 0.005 0.0001\" solmix=\"10\" solref=\"0.01 1\" solimp=\"0.95 0.99 0.001\"/>\n";
    }
  }
  // The finger's stem up to the palm (the arm's flange, 0.15 m above the tool point): drawn,
  // never colliding.
  x << "        <geom name=\"" << name << "_stem\" type=\"box\" size=\"0.008 " << g.face_half_thickness
    << " 0.07\" pos=\"0 " << side * (g.face_half_thickness + 0.002) << " 0.085\" rgba=\"0.5 0.5 0.52 1\""
    << " group=\"2\" contype=\"0\" conaffinity=\"0\"/>\n"
    << "      </body>\n";
}

// The PUMA 260 as nested bodies, one per DH link (standard DH: T_i = Rz(theta_i) Tz(d_i)
// Tx(a_i) Rx(alpha_i)): body i turns about its own z axis (joint i) and holds body i + 1 at
// (a_i, 0, d_i), rotated by alpha_i about x. Link geometry runs along those offsets. Masses are
// estimates for a PUMA 260 (about 13 kg in all, most of it in the base); the joints carry the
// reflected inertia of geared motors (armature), which also keeps the stiff position servos
// stable at the physics time step. Links collide with objects and the table (contype 4,
// conaffinity 1), not with the tools or each other (the arm service's safety checks keep those
// apart); the pedestal, welded to the world, touches nothing.
void add_arm(Xml& x, const ArmSpec& spec) {
  const robot::ArmModel puma = robot::puma260();
  const char* colour = "0.82 0.82 0.78 1";
  const char* geom_flags = "contype=\"4\" conaffinity=\"1\" condim=\"3\" friction=\"0.6 0.005 0.0001\" group=\"1\"";
  const double link_mass[6] = {2.0, 1.6, 0.9, 1.0, 0.3, 0.2};
  const double radius[6] = {0.06, 0.045, 0.045, 0.035, 0.03, 0.025};
  const double armature[6] = {0.15, 0.15, 0.1, 0.03, 0.03, 0.02};
  const double damping[6] = {30, 30, 20, 5, 5, 4};
  const double h = spec.shoulder_height;
  auto alpha_quat = [](double alpha) {
    std::ostringstream q;
    q.imbue(std::locale::classic());
    q.precision(12);
    q << std::cos(0.5 * alpha) << ' ' << std::sin(0.5 * alpha) << " 0 0";
    return q.str();
  };
  x << "    <body name=\"puma_base\" pos=\"0 0 " << h << "\">\n"
    << "      <geom name=\"puma_pedestal\" type=\"cylinder\" size=\"" << robot::SafetyConfig{}.pedestal_radius << ' ' << 0.5 * (h - 0.06) << "\" pos=\"0 0 "
    << -0.5 * (h + 0.06) << "\" rgba=\"" << colour << "\" mass=\"6\" " << geom_flags << "/>\n";
  std::string indent = "      ";
  for (int i = 0; i < 6; ++i) {
    const robot::DhLink& l = puma.links[i];
    x << indent << "<body name=\"puma_link" << i + 1 << "\"";
    if (i > 0) {  // where the previous link's DH offsets put this joint's frame
      const robot::DhLink& prev = puma.links[i - 1];
      x << " pos=\"" << prev.a << " 0 " << prev.d << "\" quat=\"" << alpha_quat(prev.alpha) << "\"";
    }
    x << ">\n"
      << indent << "  <joint name=\"puma_j" << i + 1 << "\" type=\"hinge\" axis=\"0 0 1\" limited=\"true\" range=\""
      << puma.limits.lower[i] << ' ' << puma.limits.upper[i] << "\" armature=\"" << armature[i]
      << "\" damping=\"" << damping[i] << "\"/>\n";
    // A joint housing at the body origin, and the link along its DH offsets when it has length.
    x << indent << "  <geom name=\"puma_joint" << i + 1 << "\" type=\"sphere\" size=\"" << radius[i] + 0.005
      << "\" rgba=\"0.35 0.35 0.38 1\" mass=\"" << 0.3 * link_mass[i] << "\" " << geom_flags << "/>\n";
    if (std::hypot(l.a, l.d) > 1e-9) {
      x << indent << "  <geom name=\"puma_link" << i + 1 << "_geom\" type=\"capsule\" fromto=\"0 0 0 " << l.a << " 0 "
        << l.d << "\" size=\"" << radius[i] << "\" rgba=\"" << colour << "\" mass=\"" << 0.7 * link_mass[i] << "\" "
        << geom_flags << "/>\n";
    }
    if (i == 5) {  // DH frame 6: the flange (wrist centre), where the tool is mounted
      x << indent << "  <site name=\"puma_flange\" pos=\"" << l.a << " 0 " << l.d << "\" quat=\""
        << alpha_quat(l.alpha) << "\" size=\"0.01\"/>\n";
    }
    indent += "  ";
  }
  for (int i = 0; i < 6; ++i) {
    indent.resize(indent.size() - 2);
    x << indent << "</body>\n";
  }
  x << "    </body>\n";
}

// Position servos on the six joints, within their limits.
void add_arm_actuators(Xml& x) {
  const robot::ArmModel puma = robot::puma260();
  const double kp[6] = {600, 600, 400, 80, 80, 60};
  const double max_torque[6] = {60, 60, 40, 10, 10, 8};
  for (int i = 0; i < 6; ++i) {
    x << "    <position name=\"puma_act" << i + 1 << "\" joint=\"puma_j" << i + 1 << "\" kp=\"" << kp[i]
      << "\" ctrllimited=\"true\" ctrlrange=\"" << puma.limits.lower[i] << ' ' << puma.limits.upper[i]
      << "\" forcelimited=\"true\" forcerange=\"" << -max_torque[i] << ' ' << max_torque[i] << "\"/>\n";
  }
}

}  // namespace

std::string build_mjcf(const Scene& scene) {
  validate(scene);
  const RigSpec& rs = scene.rig;
  const StereoRig rig = make_rig(rs);
  const int samples = scene.render.antialias ? 4 : 0;
  // The offscreen buffer holds the largest image drawn: a high-resolution still, or the larger
  // pinhole image a distorted camera is warped from.
  PinholeCanvas canvas = pinhole_canvas(scaled(rig.cameras[0], scene.render.snapshot_scale));
  const PinholeCanvas small = pinhole_canvas(rig.cameras[0]);
  canvas.width = std::max(canvas.width, small.width);
  canvas.height = std::max(canvas.height, small.height);
  if (canvas.width > 8192 || canvas.height > 8192)
    throw SceneError(scene.source + ": cameras.distortion: too strong to render (needs a " +
                     std::to_string(canvas.width) + "x" + std::to_string(canvas.height) +
                     " pinhole image)");

  Xml assets, bodies;
  add_material(assets, "table_mat", scene.table, false, scene.source, "table");
  add_material(assets, "backdrop_mat", scene.background, false, scene.source, "background");

  for (size_t i = 0; i < scene.objects.size(); ++i) {
    const ObjectSpec& spec = scene.objects[i];
    const ObjectModel model = model_of(spec);
    const std::string id = "obj" + std::to_string(i);
    const std::string field = "objects[" + std::to_string(i) + "]";
    // A mesh's own texture follows the file's texture coordinates once; other pictures repeat.
    double repeat = spec.appearance.repeat;
    if (spec.kind == "mesh" && !spec.mesh.texture.empty()) {
      add_picture_material(assets, id + "_mat", texture_file(spec.mesh.texture, scene.source, field + ".mesh.texture"),
                           spec.appearance.specular, spec.appearance.shininess, spec.appearance.opacity);
      repeat = 1.0;
    } else {
      add_material(assets, id + "_mat", spec.appearance, true, scene.source, field);
    }
    std::vector<const Mesh*> parts;
    for (size_t k = 0; k < model.parts.size(); ++k) {
      add_mesh(assets, id + "_part" + std::to_string(k), model.parts[k], repeat);
      parts.push_back(&model.parts[k]);
    }
    if (!model.label.faces.empty()) {
      add_picture_material(assets, id + "_label_mat", texture_file(spec.label.file, scene.source, field + ".label.file"),
                           spec.label.specular, spec.label.shininess, 1.0);
      add_mesh(assets, id + "_label", model.label, 1.0);
    }
    const double mass = spec.mass > 0 ? spec.mass : model.default_mass;
    const double friction = spec.friction > 0 ? spec.friction : model.default_friction;
    MassProperties props = shell_mass_properties(parts, mass);
    if (spec.fill > 0) {
      const double h = spec.fill * model.liquid_height, r = model.liquid_radius;
      props = combine(props, cylinder_mass_properties(r, model.liquid_bottom, h,
                                                      kWaterDensity * M_PI * r * r * h));
    }
    const Eigen::Matrix3d& I = props.inertia;
    bodies << "    <body name=\"" << id << "\" pos=\"" << spec.position.x() << ' '
           << spec.position.y() << " 0\" euler=\"0 0 " << spec.yaw << "\">\n"
           << "      <freejoint name=\"" << id << "_joint\"/>\n"
           << "      <inertial pos=\"" << vec(props.com) << "\" mass=\"" << props.mass
           << "\" fullinertia=\"" << I(0, 0) << ' ' << I(1, 1) << ' ' << I(2, 2) << ' ' << I(0, 1)
           << ' ' << I(0, 2) << ' ' << I(1, 2) << "\"/>\n";
    for (size_t k = 0; k < model.parts.size(); ++k) {
      bodies << "      <geom name=\"" << id << "_part" << k << "\" type=\"mesh\" mesh=\"" << id
             << "_part" << k << "\" material=\"" << id << "_mat\" contype=\"3\" conaffinity=\"7\""
             << " condim=\"3\" friction=\"" << friction << " 0.005 0.0001\"/>\n";
    }
    if (!model.label.faces.empty())  // drawn only: no contacts, no mass (the body's inertial is explicit)
      bodies << "      <geom name=\"" << id << "_label\" type=\"mesh\" mesh=\"" << id << "_label\" material=\""
             << id << "_label_mat\" contype=\"0\" conaffinity=\"0\"/>\n";
    bodies << "    </body>\n";
  }

  const Eigen::Vector3d pad = pusher_pad_half_size();
  const double light = scene.render.light;
  const double ambient = scene.render.ambient;
  const Eigen::Vector3d table_centre(0.5 * (kTableXMin + kTableXMax), 0, 0);

  Xml x;
  x << "<mujoco model=\"nudge_world\">\n"
    << "  <compiler angle=\"radian\"/>\n"
    << "  <option timestep=\"" << scene.physics.timestep << "\" gravity=\"0 0 -9.81\""
    << " integrator=\"Euler\" cone=\"" << (scene.physics.elliptic_cone ? "elliptic" : "pyramidal")
    << "\" impratio=\"" << scene.physics.impratio << "\" noslip_iterations=\""
    << scene.physics.noslip_iterations << "\"/>\n"
    << "  <size njmax=\"2000\" nconmax=\"500\"/>\n"
    << "  <statistic extent=\"2\" center=\"" << vec(table_centre) << "\"/>\n"
    << "  <visual>\n"
    // The overhead light's shadow map spans +-shadowclip * extent about its axis (which meets the
    // table near x = 0.45): +-1.1 m holds the whole table, at 4096 texels 0.54 mm each. At
    // MuJoCo's default (+-2 m, 2048: 2 mm texels) a label's thin sleeve was speckled with shadow
    // acne in the light (tests/unit/sim/labels_meshes_test.cpp).
    << "    <global offwidth=\"" << canvas.width << "\" offheight=\"" << canvas.height << "\"/>\n"
    << "    <quality offsamples=\"" << samples << "\" shadowsize=\"4096\"/>\n"
    << "    <headlight ambient=\"" << ambient << ' ' << ambient << ' ' << ambient
    << "\" diffuse=\"0.25 0.25 0.25\" specular=\"0.1 0.1 0.1\"/>\n"
    << "    <map znear=\"0.01\" zfar=\"20\" shadowclip=\"0.55\"/>\n"
    << "  </visual>\n"
    << "  <asset>\n"
    << assets.str() << "  </asset>\n"
    << "  <worldbody>\n"
    << "    <light name=\"overhead\" directional=\"true\" pos=\"0.25 0.3 2\" dir=\"0.1 -0.15 -1\""
    << " diffuse=\"" << light << ' ' << light << ' ' << light
    << "\" specular=\"0.2 0.2 0.2\" castshadow=\"true\"/>\n"
    << "    <light name=\"front\" directional=\"true\" pos=\"1.5 0 1.2\" dir=\"-1 0 -0.8\""
    << " diffuse=\"" << 0.5 * light << ' ' << 0.5 * light << ' ' << 0.5 * light
    << "\" specular=\"0.1 0.1 0.1\" castshadow=\"false\"/>\n"
    << "    <geom name=\"table\" type=\"plane\" pos=\"" << vec(table_centre) << "\" size=\""
    << 0.5 * (kTableXMax - kTableXMin) << ' ' << kTableHalfY << " 0.05\" material=\"table_mat\""
    << " contype=\"1\" conaffinity=\"1\" condim=\"3\" friction=\"" << scene.physics.table_friction
    << " 0.005 0.0001\"/>\n"
    // A vertical plane facing +x (towards the cameras) along the table's far edge.
    << "    <geom name=\"backdrop\" type=\"plane\" pos=\"" << kTableXMin << " 0 0.55\""
    << " euler=\"0 1.5707963267948966 0\" size=\"0.6 " << kTableHalfY + 0.4 << " 0.05\""
    << " material=\"backdrop_mat\" contype=\"0\" conaffinity=\"0\"/>\n";
  for (const CameraModel& cam : rig.cameras) {
    const Eigen::Vector3d right = cam.R.row(0).transpose();
    const Eigen::Vector3d up = -cam.R.row(1).transpose();
    x << "    <camera name=\"" << cam.name << "\" pos=\"" << vec(cam.centre()) << "\" xyaxes=\""
      << vec(right) << ' ' << vec(up) << "\" fovy=\"" << rs.fovy * 180.0 / M_PI << "\"/>\n";
  }
  x << "    <body name=\"pusher\" mocap=\"true\" pos=\"" << vec(pusher_park_position()) << "\">\n"
    << "      <geom name=\"pusher_pad\" type=\"box\" size=\"" << vec(pad) << "\""
    << " rgba=\"0.95 0.8 0.25 1\" group=\"2\" contype=\"2\" conaffinity=\"2\" condim=\"3\""
    << " friction=\"0.8 0.005 0.0001\" solmix=\"10\" solref=\"0.03 1\" solimp=\"0.6 0.9 0.01\"/>\n";
  const GripperGeometry& g = gripper_geometry();
  const double range = g.apex_for_opening(g.max_opening + 0.01);
  // The gripper's hand: a dynamic body welded to the mocap body (a mocap body has no velocity, so
  // friction could not carry a held object along with fingers attached to it directly).
  x << "    </body>\n"
    << "    <body name=\"hand\" pos=\"" << vec(pusher_park_position()) << "\">\n"
    << "      <freejoint name=\"hand_joint\"/>\n"
    << "      <inertial pos=\"0 0 0.1\" mass=\"" << g.hand_mass << "\" diaginertia=\"2e-4 2e-4 2e-4\"/>\n"
    << "      <geom name=\"hand_palm\" type=\"box\" size=\"0.015 " << 0.5 * g.max_opening + 0.012
    << " 0.006\" pos=\"0 0 0.161\" rgba=\"0.5 0.5 0.52 1\" group=\"2\" contype=\"0\" conaffinity=\"0\"/>\n";
  add_finger(x, "finger_left", 1);
  add_finger(x, "finger_right", -1);
  x << "    </body>\n"
    << bodies.str();
  if (scene.arm.present) add_arm(x, scene.arm);
  x << "  </worldbody>\n"
    << "  <equality>\n"
    << "    <weld name=\"hand_weld\" body1=\"pusher\" body2=\"hand\" relpose=\"0 0 0 1 0 0 0\""
    << " solref=\"" << g.weld_timeconst << " 1\"/>\n"
    << "  </equality>\n"
    << "  <actuator>\n";
  for (const char* finger : {"finger_left", "finger_right"})
    x << "    <position name=\"" << finger << "_act\" joint=\"" << finger << "_slide\" kp=\"" << g.kp
      << "\" ctrllimited=\"true\" ctrlrange=\"0 " << range << "\" forcelimited=\"true\" forcerange=\""
      << -g.max_force << ' ' << g.max_force << "\"/>\n";
  if (scene.arm.present) add_arm_actuators(x);
  x << "  </actuator>\n"
    << "</mujoco>\n";
  return x.str();
}

}  // namespace nudge::sim
