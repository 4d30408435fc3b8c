#include "nudge/sim/mesh_file.hpp"

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>
#include <tuple>

namespace nudge::sim {

namespace {

[[noreturn]] void fail(const std::string& path, const std::string& what) {
  throw MeshFileError(path + ": " + what);
}

std::string lower_extension(const std::string& path) {
  const auto dot = path.find_last_of('.');
  if (dot == std::string::npos || path.find('/', dot) != std::string::npos) return "";
  std::string ext = path.substr(dot);
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

std::string read_all(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(path, "cannot read the file");
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// An OBJ index (1-based, or negative = from the end) to a 0-based one.
int obj_index(const std::string& token, size_t count, const std::string& path, int line) {
  char* end = nullptr;
  const long i = std::strtol(token.c_str(), &end, 10);
  const long n = static_cast<long>(count);
  const long k = i > 0 ? i - 1 : n + i;
  if (end == token.c_str() || *end != '\0' || i == 0 || k < 0 || k >= n)
    fail(path, "line " + std::to_string(line) + ": index '" + token + "' out of range (1.." +
                   std::to_string(n) + ")");
  return static_cast<int>(k);
}

Mesh read_obj(const std::string& path) {
  std::istringstream in(read_all(path));
  std::vector<Eigen::Vector3f> positions;
  std::vector<Eigen::Vector2f> uvs;
  std::map<std::pair<int, int>, int> vertex_of;  // (position, uv) -> mesh vertex
  Mesh mesh;
  bool any_without_uv = false;
  std::string text;
  int line = 0;
  while (std::getline(in, text)) {
    ++line;
    std::istringstream row(text);
    std::string tag;
    if (!(row >> tag) || tag[0] == '#') continue;
    if (tag == "v") {
      float x, y, z;
      if (!(row >> x >> y >> z) || !std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z))
        fail(path, "line " + std::to_string(line) + ": a vertex needs three finite numbers");
      positions.emplace_back(x, y, z);
    } else if (tag == "vt") {
      float u, v = 0;
      if (!(row >> u)) fail(path, "line " + std::to_string(line) + ": vt needs numbers");
      row >> v;
      uvs.emplace_back(u, v);
    } else if (tag == "f") {
      std::vector<int> polygon;
      std::string corner;
      while (row >> corner) {
        const auto slash = corner.find('/');
        const int p = obj_index(corner.substr(0, slash), positions.size(), path, line);
        int t = -1;
        if (slash != std::string::npos) {
          const auto slash2 = corner.find('/', slash + 1);
          const std::string uv = corner.substr(slash + 1, slash2 == std::string::npos ? std::string::npos : slash2 - slash - 1);
          if (!uv.empty()) t = obj_index(uv, uvs.size(), path, line);
        }
        if (t < 0) any_without_uv = true;
        auto [it, fresh] = vertex_of.emplace(std::make_pair(p, t), static_cast<int>(mesh.vertices.size()));
        if (fresh) {
          mesh.vertices.push_back(positions[p]);
          mesh.texcoords.push_back(t >= 0 ? uvs[t] : Eigen::Vector2f(0, 0));
        }
        polygon.push_back(it->second);
      }
      if (polygon.size() < 3) fail(path, "line " + std::to_string(line) + ": a face needs three corners");
      for (size_t k = 1; k + 1 < polygon.size(); ++k)
        mesh.faces.emplace_back(polygon[0], polygon[k], polygon[k + 1]);
    }
    // Other statements (vn, o, g, s, usemtl, mtllib, l, ...) do not change the shape.
  }
  if (any_without_uv || uvs.empty()) mesh.texcoords.clear();
  return mesh;
}

// Vertices of an STL are per facet: shared corners are merged by exact position.
int stl_vertex(Mesh& mesh, std::map<std::tuple<float, float, float>, int>& index, const Eigen::Vector3f& p) {
  auto [it, fresh] = index.emplace(std::make_tuple(p.x(), p.y(), p.z()), static_cast<int>(mesh.vertices.size()));
  if (fresh) mesh.vertices.push_back(p);
  return it->second;
}

void add_stl_facet(Mesh& mesh, std::map<std::tuple<float, float, float>, int>& index, const Eigen::Vector3f* c,
                   const std::string& path) {
  for (int k = 0; k < 3; ++k)
    if (!c[k].allFinite()) fail(path, "a facet has a coordinate that is not finite");
  const int a = stl_vertex(mesh, index, c[0]), b = stl_vertex(mesh, index, c[1]), d = stl_vertex(mesh, index, c[2]);
  if (a != b && b != d && a != d) mesh.faces.emplace_back(a, b, d);
}

Mesh read_stl(const std::string& path) {
  const std::string data = read_all(path);
  Mesh mesh;
  std::map<std::tuple<float, float, float>, int> index;
  // Binary: 80-byte header, uint32 count, 50 bytes per facet. Some binary files start with
  // "solid" too, so the size decides.
  if (data.size() >= 84) {
    uint32_t count = 0;
    std::memcpy(&count, data.data() + 80, 4);
    if (data.size() == 84 + 50ull * count) {
      for (uint32_t i = 0; i < count; ++i) {
        const char* facet = data.data() + 84 + 50ull * i + 12;  // skip the normal
        Eigen::Vector3f c[3];
        for (int k = 0; k < 3; ++k) std::memcpy(c[k].data(), facet + 12 * k, 12);
        add_stl_facet(mesh, index, c, path);
      }
      return mesh;
    }
  }
  if (data.compare(0, 5, "solid") != 0)
    fail(path, "neither a binary STL (size does not match its facet count) nor an ASCII one (no 'solid')");
  std::istringstream in(data);
  std::string word;
  Eigen::Vector3f corner[3];
  int corners = 0;
  while (in >> word) {
    if (word == "vertex") {
      if (corners == 3) fail(path, "a facet with more than three vertices");
      if (!(in >> corner[corners].x() >> corner[corners].y() >> corner[corners].z()))
        fail(path, "a vertex needs three numbers");
      ++corners;
    } else if (word == "endfacet") {
      if (corners != 3) fail(path, "a facet without three vertices");
      add_stl_facet(mesh, index, corner, path);
      corners = 0;
    }
  }
  return mesh;
}

}  // namespace

Mesh read_mesh_file(const std::string& path) {
  const std::string ext = lower_extension(path);
  Mesh mesh;
  if (ext == ".obj")
    mesh = read_obj(path);
  else if (ext == ".stl")
    mesh = read_stl(path);
  else
    fail(path, "not a mesh file MuJoCo loads here (expected .obj or .stl)");
  if (mesh.faces.empty()) fail(path, "has no triangles");
  if (std::fabs(mesh.volume()) < 1e-15)
    fail(path, "encloses no volume (flat or open), so it cannot be a solid object");
  return mesh;
}

}  // namespace nudge::sim
