#include "nudge/sim/objects.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace nudge::sim {

namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;

// Turns the faces of `mesh` outwards if its signed volume is negative.
void orient_outwards(Mesh& mesh) {
  if (mesh.volume() < 0) {
    for (auto& f : mesh.faces) std::swap(f[1], f[2]);
  }
}

// A closed tube of radius `tube_r` swept along `centre` (open curve), with flat end caps.
// Texture coordinates: 1 unit per `v_unit` metres along the tube and around it.
Mesh sweep_tube(const std::vector<Vector3d>& centre, double tube_r, int sides, double v_unit) {
  Mesh mesh;
  const int n = static_cast<int>(centre.size());
  std::vector<double> arc(n, 0.0);
  for (int i = 1; i < n; ++i) arc[i] = arc[i - 1] + (centre[i] - centre[i - 1]).norm();
  const double end_v = arc[n - 1] / v_unit;
  const double around = 2 * M_PI * tube_r / v_unit;
  for (int i = 0; i < n; ++i) {
    const Vector3d tangent =
        (centre[std::min(i + 1, n - 1)] - centre[std::max(i - 1, 0)]).normalized();
    // The curve lies in a plane containing y = 0; use y as the binormal.
    const Vector3d binormal(0, 1, 0);
    const Vector3d normal = binormal.cross(tangent).normalized();
    for (int j = 0; j <= sides; ++j) {
      const double b = 2 * M_PI * j / sides;
      const Vector3d p = centre[i] + tube_r * (std::cos(b) * normal + std::sin(b) * binormal);
      mesh.vertices.push_back(p.cast<float>());
      mesh.texcoords.emplace_back(static_cast<float>(around * j / sides),
                                  static_cast<float>(arc[i] / v_unit));
    }
  }
  const int ring = sides + 1;
  for (int i = 0; i + 1 < n; ++i) {
    for (int j = 0; j < sides; ++j) {
      const int a = i * ring + j, b = a + 1, c = a + ring, d = c + 1;
      mesh.faces.emplace_back(a, c, b);
      mesh.faces.emplace_back(b, c, d);
    }
  }
  // End caps: a fan around the centre point of each end.
  for (int end = 0; end < 2; ++end) {
    const int i = end == 0 ? 0 : n - 1;
    const int centre_index = static_cast<int>(mesh.vertices.size());
    mesh.vertices.push_back(centre[i].cast<float>());
    mesh.texcoords.emplace_back(0.5f, end == 0 ? 0.0f : static_cast<float>(end_v));
    for (int j = 0; j < sides; ++j) {
      const int a = i * ring + j, b = a + 1;
      if (end == 0)
        mesh.faces.emplace_back(centre_index, b, a);
      else
        mesh.faces.emplace_back(centre_index, a, b);
    }
  }
  return mesh;
}

std::vector<Vector2d> cup_profile() {
  return {{0, 0},          {0.026, 0},      {0.0278, 0.0008}, {0.0285, 0.003},
          {0.0395, 0.087}, {0.0400, 0.0895}, {0.0390, 0.0905}, {0.0372, 0.0900},
          {0.0258, 0.010}, {0.0245, 0.007},  {0.020, 0.006},   {0, 0.006}};
}

std::vector<Vector2d> mug_profile() {
  return {{0, 0},         {0.039, 0},     {0.0405, 0.0008}, {0.041, 0.003},
          {0.041, 0.093}, {0.0402, 0.095}, {0.0373, 0.095},  {0.0365, 0.093},
          {0.0365, 0.011}, {0.034, 0.008},  {0, 0.008}};
}

std::vector<Vector2d> bottle_profile() {
  return {{0, 0},          {0.031, 0},       {0.0340, 0.0012}, {0.0350, 0.004},
          {0.0350, 0.125}, {0.0340, 0.137},  {0.0310, 0.147},  {0.0260, 0.156},
          {0.0200, 0.164}, {0.0155, 0.170},  {0.0145, 0.175},  {0.0145, 0.182},
          {0.0160, 0.182}, {0.0160, 0.1985}, {0.0150, 0.200},  {0, 0.200}};
}

std::vector<Vector2d> can_profile() {
  return {{0, 0},          {0.026, 0},      {0.0315, 0.004}, {0.0330, 0.010},
          {0.0330, 0.110}, {0.0300, 0.119}, {0.0295, 0.122}, {0.0285, 0.122},
          {0.0280, 0.120}, {0, 0.120}};
}

// A colour marker: a sleeve on a pendulum arm (thesis sec. 5.4, fig. 5.7), an 85 mm long, 24 mm
// thick ellipsoid. Its image centroid lies on the projection of its axis, which the pendulum
// experiment uses as ground truth.
std::vector<Vector2d> marker_profile() {
  std::vector<Vector2d> p;
  const int n = 16;
  for (int i = 0; i <= n; ++i) {
    const double phi = M_PI * i / n;
    p.emplace_back(i == 0 || i == n ? 0.0 : 0.012 * std::sin(phi), 0.0425 * (1 - std::cos(phi)));
  }
  return p;
}

ObjectModel from_profile(const std::string& kind, const std::vector<Vector2d>& profile,
                         int segments, double mass, double friction, double liquid_radius,
                         double liquid_bottom, double liquid_height) {
  ObjectModel model;
  model.kind = kind;
  model.profile = profile;
  model.parts.push_back(revolve(profile, segments));
  for (const auto& p : profile) {
    model.height = std::max(model.height, p.y());
    model.max_radius = std::max(model.max_radius, p.x());
    if (p.y() <= 1e-9) model.base_radius = std::max(model.base_radius, p.x());
  }
  model.default_mass = mass;
  model.default_friction = friction;
  model.liquid_radius = liquid_radius;
  model.liquid_bottom = liquid_bottom;
  model.liquid_height = liquid_height;
  return model;
}

}  // namespace

double ObjectModel::radius_at(double z) const {
  double r = 0;
  if (profile.empty()) {  // a mesh object
    for (const Mesh& part : parts)
      for (const auto& v : part.vertices)
        if (std::fabs(v.z() - z) <= 0.002) r = std::max(r, static_cast<double>(v.head<2>().norm()));
    return r;
  }
  for (size_t i = 0; i + 1 < profile.size(); ++i) {
    const Vector2d& a = profile[i];
    const Vector2d& b = profile[i + 1];
    const double lo = std::min(a.y(), b.y()), hi = std::max(a.y(), b.y());
    if (z < lo || z > hi) continue;
    if (hi - lo < 1e-12) {
      r = std::max({r, a.x(), b.x()});
    } else {
      const double f = (z - a.y()) / (b.y() - a.y());
      r = std::max(r, a.x() + f * (b.x() - a.x()));
    }
  }
  return r;
}

double Mesh::area() const {
  double a = 0;
  for (const auto& f : faces) {
    const Vector3d p0 = vertices[f[0]].cast<double>(), p1 = vertices[f[1]].cast<double>(),
                   p2 = vertices[f[2]].cast<double>();
    a += 0.5 * (p1 - p0).cross(p2 - p0).norm();
  }
  return a;
}

double Mesh::volume() const {
  double v = 0;
  for (const auto& f : faces) {
    const Vector3d p0 = vertices[f[0]].cast<double>(), p1 = vertices[f[1]].cast<double>(),
                   p2 = vertices[f[2]].cast<double>();
    v += p0.dot(p1.cross(p2)) / 6.0;
  }
  return v;
}

MassProperties shell_mass_properties(const std::vector<const Mesh*>& meshes, double mass) {
  double area = 0;
  Vector3d first = Vector3d::Zero();
  Eigen::Matrix3d second = Eigen::Matrix3d::Zero();  // integral of p p^T dA about the origin
  for (const Mesh* mesh : meshes) {
    for (const auto& f : mesh->faces) {
      const Vector3d a = mesh->vertices[f[0]].cast<double>(), b = mesh->vertices[f[1]].cast<double>(),
                     c = mesh->vertices[f[2]].cast<double>();
      const double t = 0.5 * (b - a).cross(c - a).norm();
      if (t <= 0) continue;
      const Vector3d s = a + b + c;
      area += t;
      first += t * s / 3.0;
      second += t / 12.0 * (a * a.transpose() + b * b.transpose() + c * c.transpose() +
                            s * s.transpose());
    }
  }
  if (area <= 0) throw std::invalid_argument("shell_mass_properties: meshes have no area");
  MassProperties props;
  const double sigma = mass / area;
  props.mass = mass;
  props.com = first / area;
  const Eigen::Matrix3d c_origin = sigma * second;
  const Eigen::Matrix3d i_origin =
      c_origin.trace() * Eigen::Matrix3d::Identity() - c_origin;
  const Vector3d& g = props.com;
  props.inertia = i_origin - mass * (g.squaredNorm() * Eigen::Matrix3d::Identity() - g * g.transpose());
  return props;
}

MassProperties cylinder_mass_properties(double radius, double z0, double height, double mass) {
  MassProperties props;
  props.mass = mass;
  props.com = Vector3d(0, 0, z0 + 0.5 * height);
  const double side = mass * (3 * radius * radius + height * height) / 12.0;
  props.inertia = Eigen::Vector3d(side, side, 0.5 * mass * radius * radius).asDiagonal();
  return props;
}

MassProperties combine(const MassProperties& a, const MassProperties& b) {
  MassProperties out;
  out.mass = a.mass + b.mass;
  if (!(out.mass > 0)) return out;
  out.com = (a.mass * a.com + b.mass * b.com) / out.mass;
  auto shifted = [&out](const MassProperties& p) {  // parallel axis theorem to the joint com
    const Vector3d d = p.com - out.com;
    return Eigen::Matrix3d(p.inertia + p.mass * (d.squaredNorm() * Eigen::Matrix3d::Identity() -
                                                 d * d.transpose()));
  };
  out.inertia = shifted(a) + shifted(b);
  return out;
}

Mesh revolve(const std::vector<Vector2d>& profile, int segments) {
  if (profile.size() < 3) throw std::invalid_argument("revolve: profile needs >= 3 points");
  if (segments < 3) throw std::invalid_argument("revolve: segments must be >= 3");
  const int n = static_cast<int>(profile.size());
  std::vector<double> arc(n, 0.0);
  for (int i = 1; i < n; ++i) arc[i] = arc[i - 1] + (profile[i] - profile[i - 1]).norm();
  double r_max = 0;
  for (const auto& p : profile) r_max = std::max(r_max, p.x());
  const double v_unit = 2 * M_PI * std::max(r_max, 1e-6);  // v = 1 per circumference: square checks

  Mesh mesh;
  // Vertex index of profile point i at segment j (poles are a single vertex).
  std::vector<std::vector<int>> index(n);
  for (int i = 0; i < n; ++i) {
    const double r = profile[i].x(), z = profile[i].y();
    const float v = static_cast<float>(arc[i] / v_unit);
    if (r <= 1e-12) {
      index[i].assign(segments + 1, static_cast<int>(mesh.vertices.size()));
      mesh.vertices.emplace_back(0.0f, 0.0f, static_cast<float>(z));
      mesh.texcoords.emplace_back(0.5f, v);
      continue;
    }
    for (int j = 0; j <= segments; ++j) {  // j = segments duplicates j = 0 (texture seam)
      const double phi = 2 * M_PI * j / segments;
      index[i].push_back(static_cast<int>(mesh.vertices.size()));
      mesh.vertices.emplace_back(static_cast<float>(r * std::cos(phi)),
                                 static_cast<float>(r * std::sin(phi)), static_cast<float>(z));
      mesh.texcoords.emplace_back(static_cast<float>(j) / segments, v);
    }
  }
  for (int i = 0; i + 1 < n; ++i) {
    for (int j = 0; j < segments; ++j) {
      const int a = index[i][j], b = index[i][j + 1], c = index[i + 1][j], d = index[i + 1][j + 1];
      if (a != b) mesh.faces.emplace_back(a, b, d);
      if (c != d) mesh.faces.emplace_back(a, d, c);
    }
  }
  orient_outwards(mesh);
  return mesh;
}

std::vector<std::string> object_kinds() { return {"bottle", "can", "cup", "marker", "mug"}; }

bool is_object_kind(const std::string& kind) {
  const auto kinds = object_kinds();
  return std::find(kinds.begin(), kinds.end(), kind) != kinds.end();
}

ObjectModel make_object(const std::string& kind, int segments) {
  // Liquid space: an inscribed cylinder (the cup's tapered inside is averaged; the bottle's
  // shoulder and neck are left out).
  if (kind == "cup") return from_profile(kind, cup_profile(), segments, 0.25, 0.5, 0.031, 0.006, 0.080);
  if (kind == "bottle") return from_profile(kind, bottle_profile(), segments, 0.04, 0.45, 0.0335, 0.002, 0.125);
  if (kind == "can") return from_profile(kind, can_profile(), segments, 0.02, 0.4, 0.032, 0.004, 0.110);
  if (kind == "marker") return from_profile(kind, marker_profile(), segments, 0.005, 0.5, 0.0, 0.0, 0.0);
  if (kind == "mug") {
    ObjectModel model = from_profile(kind, mug_profile(), segments, 0.35, 0.5, 0.0365, 0.008, 0.085);
    // Handle: an elliptical arc on the +x side, its ends buried 4 mm in the wall.
    const double wall = 0.041, zc = 0.050, rx = 0.030, rz = 0.027, tube = 0.0055;
    std::vector<Vector3d> centre;
    const int steps = 24;
    for (int k = 0; k <= steps; ++k) {
      const double a = -M_PI / 2 + M_PI * k / steps;
      centre.emplace_back(wall - 0.004 + rx * std::cos(a), 0.0, zc + rz * std::sin(a));
    }
    Mesh handle = sweep_tube(centre, tube, 16, 2 * M_PI * model.max_radius);
    orient_outwards(handle);
    model.parts.push_back(std::move(handle));
    return model;
  }
  std::string known;
  for (const auto& k : object_kinds()) known += (known.empty() ? "" : ", ") + k;
  throw std::invalid_argument("unknown object kind '" + kind + "' (known: " + known + ")");
}

std::pair<double, double> default_label_band(const std::string& kind) {
  if (kind == "bottle") return {0.030, 0.120};
  if (kind == "can") return {0.015, 0.105};
  if (kind == "cup") return {0.025, 0.080};
  if (kind == "mug") return {0.015, 0.085};
  throw std::invalid_argument("a " + kind + " has no place for a label");
}

Mesh label_sleeve(const ObjectModel& model, double bottom, double top, int segments) {
  if (!(bottom >= 0 && top > bottom + 1e-3 && top <= model.height))
    throw std::invalid_argument("label band [" + std::to_string(bottom) + ", " + std::to_string(top) +
                                "] m must lie within the object's height [0, " + std::to_string(model.height) + "]");
  if (segments < 3) throw std::invalid_argument("label_sleeve: segments must be >= 3");
  constexpr double kGap = 1e-4, kThickness = 3e-4;
  const int rows = std::max(2, static_cast<int>(std::ceil((top - bottom) / 0.002)) + 1);
  Mesh mesh;
  // Two skins (outer = 0, inner = 1), each (rows) x (segments + 1) vertices; the seam is duplicated
  // for the texture.
  const int ring = segments + 1, skin = rows * ring;
  for (int s = 0; s < 2; ++s) {
    for (int i = 0; i < rows; ++i) {
      const double z = top - (top - bottom) * i / (rows - 1);  // from the top down: v = 0 at the top
      const double r = model.radius_at(z) + kGap + (s == 0 ? kThickness : 0.0);
      for (int j = 0; j <= segments; ++j) {
        const double phi = 2 * M_PI * j / segments;
        mesh.vertices.emplace_back(static_cast<float>(r * std::cos(phi)), static_cast<float>(r * std::sin(phi)),
                                   static_cast<float>(z));
        mesh.texcoords.emplace_back(static_cast<float>(j) / segments, static_cast<float>(i) / (rows - 1));
      }
    }
  }
  auto at = [&](int s, int i, int j) { return s * skin + i * ring + j; };
  for (int i = 0; i + 1 < rows; ++i)
    for (int j = 0; j < segments; ++j) {
      // Row i is above row i + 1. Outer skin faces out, inner skin faces in.
      const int a = at(0, i + 1, j), b = at(0, i + 1, j + 1), c = at(0, i, j), d = at(0, i, j + 1);
      mesh.faces.emplace_back(a, b, d);
      mesh.faces.emplace_back(a, d, c);
      const int e = at(1, i + 1, j), f = at(1, i + 1, j + 1), g = at(1, i, j), h = at(1, i, j + 1);
      mesh.faces.emplace_back(e, h, f);
      mesh.faces.emplace_back(e, g, h);
    }
  // Rims joining the skins: facing up at the top (row 0), down at the bottom (row rows - 1).
  for (int j = 0; j < segments; ++j) {
    const int o0 = at(0, 0, j), o1 = at(0, 0, j + 1), i0 = at(1, 0, j), i1 = at(1, 0, j + 1);
    mesh.faces.emplace_back(o0, o1, i1);
    mesh.faces.emplace_back(o0, i1, i0);
    const int p0 = at(0, rows - 1, j), p1 = at(0, rows - 1, j + 1), k0 = at(1, rows - 1, j), k1 = at(1, rows - 1, j + 1);
    mesh.faces.emplace_back(p0, k1, p1);
    mesh.faces.emplace_back(p0, k0, k1);
  }
  return mesh;
}

ObjectModel mesh_object(const Mesh& file_mesh, double scale, const Eigen::Vector3d& rotation) {
  if (!(scale > 0) || !std::isfinite(scale)) throw std::invalid_argument("mesh scale must be positive");
  if (file_mesh.vertices.empty() || file_mesh.faces.empty()) throw std::invalid_argument("the mesh is empty");
  const Eigen::Matrix3d turn = (Eigen::AngleAxisd(rotation.z(), Vector3d::UnitZ()) *
                                Eigen::AngleAxisd(rotation.y(), Vector3d::UnitY()) *
                                Eigen::AngleAxisd(rotation.x(), Vector3d::UnitX()))
                                   .toRotationMatrix();
  Mesh mesh = file_mesh;
  Eigen::AlignedBox3d box;
  for (auto& v : mesh.vertices) {
    v = (turn * (scale * v.cast<double>())).cast<float>();
    box.extend(v.cast<double>());
  }
  const Vector3d shift(-box.center().x(), -box.center().y(), -box.min().z());
  for (auto& v : mesh.vertices) v += shift.cast<float>();
  const Vector3d size = box.sizes();
  if (size.minCoeff() < 1e-4)
    throw std::invalid_argument("the scaled mesh is flat (bounding box " + std::to_string(size.x()) + " x " +
                                std::to_string(size.y()) + " x " + std::to_string(size.z()) + " m)");
  ObjectModel model;
  model.kind = "mesh";
  model.height = size.z();
  for (const auto& v : mesh.vertices) {
    const double r = v.head<2>().cast<double>().norm();
    model.max_radius = std::max(model.max_radius, r);
    if (v.z() <= 0.002f) model.base_radius = std::max(model.base_radius, r);
  }
  if (mesh.texcoords.size() == mesh.vertices.size()) {
    for (auto& t : mesh.texcoords) t.y() = 1.0f - t.y();
  } else {  // a cylindrical projection, as revolve()'s: u = angle / 2pi, v = height / circumference
    mesh.texcoords.clear();
    const double circumference = 2 * M_PI * std::max(model.max_radius, 1e-6);
    for (const auto& v : mesh.vertices)
      mesh.texcoords.emplace_back(static_cast<float>(std::atan2(v.y(), v.x()) / (2 * M_PI) + 0.5),
                                  static_cast<float>(v.z() / circumference));
  }
  orient_outwards(mesh);
  model.parts.push_back(std::move(mesh));
  model.default_mass = 0.1;
  model.default_friction = 0.5;
  return model;
}

}  // namespace nudge::sim
