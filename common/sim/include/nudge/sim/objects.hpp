#pragma once
// The object library: household objects generated from profiles. A body of revolution is a
// closed (r, z) profile curve turned about the object's z axis into a triangle mesh with texture
// coordinates (u = angle / 2pi, v = arc length along the profile / the widest circumference, so
// that a texture's cells are square at the widest radius). A mug adds a
// handle, a tube swept along an arc. Object frame: origin at the centre of the base on the table,
// z up along the symmetry axis; a mug's handle points along +x.
//
// Masses and inertias are those of thin shells (empty objects): the mass is spread over the
// surface, so the centre of mass and the inertia follow from the triangles.
#include <Eigen/Core>

#include <string>
#include <utility>
#include <vector>

namespace nudge::sim {

struct Mesh {
  std::vector<Eigen::Vector3f> vertices;
  std::vector<Eigen::Vector2f> texcoords;  // one per vertex
  std::vector<Eigen::Vector3i> faces;      // counter-clockwise seen from outside
  double area() const;
  double volume() const;  // signed: positive when the faces point outwards
};

struct MassProperties {
  double mass = 0;
  Eigen::Vector3d com = Eigen::Vector3d::Zero();      // object frame
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();  // about the com, object-frame axes
};

// Mass properties of a thin shell of total mass `mass` spread uniformly over the meshes' area.
MassProperties shell_mass_properties(const std::vector<const Mesh*>& meshes, double mass);
// A solid upright cylinder (axis z) of `radius`, from height z0 to z0 + height.
MassProperties cylinder_mass_properties(double radius, double z0, double height, double mass);
// Two bodies rigidly joined.
MassProperties combine(const MassProperties& a, const MassProperties& b);

constexpr double kWaterDensity = 1000.0;  // kg/m^3

struct ObjectModel {
  std::string kind;
  std::vector<Eigen::Vector2d> profile;  // (r, z) of the body of revolution, axis to axis
  std::vector<Mesh> parts;    // each part is one mesh geom (its convex hull collides)
  double height = 0;          // m, top of the object above its base
  double base_radius = 0;     // m, radius of the footprint
  double max_radius = 0;      // m, widest point of the body of revolution (handle excluded)
  double default_mass = 0;    // kg
  double default_friction = 0.5;
  // The space a liquid can fill, as a cylinder: radius, bottom and height (fill = 1).
  double liquid_radius = 0, liquid_bottom = 0, liquid_height = 0;

  // Drawn only (no collision, no mass): a label wrapped round the body; empty without one.
  Mesh label;

  // Outer radius of the body of revolution at height z (largest r where the profile crosses z;
  // handle excluded); 0 outside [0, height]. Where a pad at that height first touches the object.
  // A mesh object (no profile): the largest horizontal distance of its vertices from the z axis
  // within 2 mm of z.
  double radius_at(double z) const;
};

// Kinds known to the library, e.g. {"bottle", "can", "cup", "mug"}.
std::vector<std::string> object_kinds();
bool is_object_kind(const std::string& kind);

// Builds the model of a kind; throws std::invalid_argument for an unknown kind.
// `segments`: number of facets around the axis.
ObjectModel make_object(const std::string& kind, int segments = 48);

// The band of the side a label covers by default: the straight wall of a bottle or a can, most
// of a cup's or mug's side. (bottom, top) heights in metres; throws std::invalid_argument for a
// kind without one (marker).
std::pair<double, double> default_label_band(const std::string& kind);

// A label wrapped once round a body of revolution over the heights [bottom, top]: a thin closed
// sleeve (0.3 mm thick) standing 0.1 mm off the surface, following the profile. Texture
// coordinates: u = angle / 2pi (the picture's width once round, its left edge at the object's +x
// axis, running counter-clockwise seen from above, i.e. left to right seen from outside), v = 0 at
// the top of the band and 1 at its bottom (the picture's top row up). Throws std::invalid_argument
// when the band is empty or leaves [0, height].
Mesh label_sleeve(const ObjectModel& model, double bottom, double top, int segments);

// An object made of a mesh file's triangles (read_mesh_file(), mesh_file.hpp): scaled, turned by
// the x-y-z Euler angles `rotation` (rad, about fixed axes, x first), then moved so that its lowest
// point is on the table (z = 0) and its bounding box is centred on the z axis. Faces are turned
// outwards. Texture coordinates: the file's (v flipped: OBJ's v = 0 is the picture's bottom row),
// or, when it has none, a cylindrical projection about z like the library's objects'.
// kind "mesh", default mass 0.1 kg. Throws std::invalid_argument for a bad scale or a flat result.
ObjectModel mesh_object(const Mesh& file_mesh, double scale, const Eigen::Vector3d& rotation);

// Turns a profile about the z axis. `profile` goes from a point on the axis (r = 0) along the
// object's surface to another point on the axis (e.g. bottom centre, out, up the wall, in, top
// centre). Either direction works: the faces are turned to point outwards.
Mesh revolve(const std::vector<Eigen::Vector2d>& profile, int segments);

}  // namespace nudge::sim
