#pragma once
// Meshes from a user's own files: Wavefront OBJ (v, vt, f; polygons are fanned into triangles;
// texture coordinates kept) and STL (binary or ASCII; no texture coordinates). The loader is ours,
// not MuJoCo's, so that the object's size, mass and ground truth are known before the model is
// compiled, and so that a bad file is an error naming it and the line.
#include "nudge/sim/objects.hpp"

#include <stdexcept>
#include <string>

namespace nudge::sim {

// A mesh file that cannot be read or makes no solid: the message names the file (and the line).
class MeshFileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Reads an .obj or .stl file (by extension, case-insensitive). Vertices are in the file's units
// and frame. `texcoords` is empty when the file has none (STL, or an OBJ without vt).
// Throws MeshFileError.
Mesh read_mesh_file(const std::string& path);

}  // namespace nudge::sim
