// Objects worth learning: labels wrapped round bottles and cans, objects from a user's mesh files,
// their ground truth (masks, surface coordinates), and errors naming the file and the field.
#include "sim_test_helpers.hpp"

#include "nudge/sim/mesh_file.hpp"
#include "nudge/sim/textures.hpp"
#include "nudge/sim/truth_images.hpp"

#include <cstdlib>
#include <filesystem>

using namespace nudge::sim;
using namespace nudge::sim::test;

namespace {

// A fresh empty directory for one test's files, removed with it.
struct TempDir {
  explicit TempDir(const std::string& name)
      : path("/tmp/nudge_sim_test_" + std::to_string(::getpid()) + "_" + name) {
    std::filesystem::remove_all(path);
    std::filesystem::create_directories(path);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path, ec);
  }
  const std::string path;
};

// A picture whose left half is red and right half blue, as a JPEG (MuJoCo reads PNG only).
std::string red_blue_jpeg(const std::string& dir) {
  cv::Mat picture(64, 128, CV_8UC3, cv::Scalar(0, 0, 255));
  picture(cv::Rect(64, 0, 64, 64)).setTo(cv::Scalar(255, 0, 0));
  const std::string path = dir + "/label.jpg";
  cv::imwrite(path, picture);
  return path;
}

// An upright box, Y up (as many modelling tools write), in millimetres: 40 x 100 x 60 (x, y, z),
// one texture coordinate per face corner.
std::string box_obj(const std::string& dir) {
  const std::string path = dir + "/box.obj";
  std::ofstream out(path);
  out << "# box\n";
  for (int i = 0; i < 8; ++i)
    out << "v " << (i & 1 ? 20 : -20) << ' ' << (i & 2 ? 100 : 0) << ' ' << (i & 4 ? 30 : -30) << "\n";
  out << "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n";
  // Quads, counter-clockwise seen from outside.
  const int faces[6][4] = {{1, 3, 7, 5}, {2, 6, 8, 4}, {1, 5, 6, 2}, {3, 4, 8, 7}, {1, 2, 4, 3}, {5, 7, 8, 6}};
  for (const auto& f : faces) out << "f " << f[0] << "/1 " << f[1] << "/2 " << f[2] << "/3 " << f[3] << "/4\n";
  return path;
}

// The same box (in metres, z up) as a binary STL.
std::string box_stl(const std::string& dir) {
  const std::string path = dir + "/box.stl";
  const Mesh box = mesh_object(read_mesh_file(box_obj(dir)), 0.001, Eigen::Vector3d(M_PI / 2, 0, 0)).parts[0];
  std::ofstream out(path, std::ios::binary);
  char header[80] = "binary box";
  out.write(header, 80);
  const uint32_t n = static_cast<uint32_t>(box.faces.size());
  out.write(reinterpret_cast<const char*>(&n), 4);
  for (const auto& f : box.faces) {
    const float normal[3] = {0, 0, 0};
    out.write(reinterpret_cast<const char*>(normal), 12);
    for (int k = 0; k < 3; ++k) out.write(reinterpret_cast<const char*>(box.vertices[f[k]].data()), 12);
    const uint16_t attributes = 0;
    out.write(reinterpret_cast<const char*>(&attributes), 2);
  }
  return path;
}

std::string scene_error(const Scene& scene) {
  try {
    World world(scene);
  } catch (const SceneError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(SimLabels, SleeveWrapsTheBandJustOutsideTheBody) {
  const ObjectModel bottle = make_object("bottle");
  const Mesh sleeve = label_sleeve(bottle, 0.03, 0.12, 48);
  EXPECT_GT(sleeve.volume(), 0);  // closed, faces outwards
  EXPECT_NEAR(sleeve.volume(), M_PI * (std::pow(0.0354, 2) - std::pow(0.0351, 2)) * 0.09, 2e-7);
  ASSERT_EQ(sleeve.texcoords.size(), sleeve.vertices.size());
  for (size_t k = 0; k < sleeve.vertices.size(); ++k) {
    const Eigen::Vector3f& v = sleeve.vertices[k];
    EXPECT_GE(v.z(), 0.03f - 1e-6f);
    EXPECT_LE(v.z(), 0.12f + 1e-6f);
    const double gap = v.head<2>().norm() - bottle.radius_at(v.z());
    EXPECT_GT(gap, 0.5e-4);
    EXPECT_LT(gap, 5e-4);
    // v = 0 at the top of the band, 1 at its bottom (the picture's top row up).
    EXPECT_NEAR(sleeve.texcoords[k].y(), (0.12 - v.z()) / 0.09, 1e-4);
  }
  EXPECT_THROW(label_sleeve(bottle, 0.1, 0.25, 48), std::invalid_argument);  // above the top
  EXPECT_THROW(default_label_band("marker"), std::invalid_argument);
}

// A JPEG label is converted into the texture cache (not beside the picture), drawn round the
// bottle the right way round, and counted in the bottle's mask.
// The label is a thin sleeve just outside the body. With a coarse shadow map (2 mm texels) the
// overhead light's depth test flickered between the sleeve's walls and speckled a lit label with
// dark dots, which no camera sees and which SIFT took for features (a bottle lying in the light
// was not recognised). The shadow map now covers the table only, at 4096 texels: a lying bottle's
// label looks the same with shadows on as off, apart from real shadow.
TEST(SimLabels, ALabelInTheLightIsNotSpeckledByItsOwnShadow) {
  const TempDir label_dir("grey_label");
  const std::string label = label_dir.path + "/grey.png";
  cv::imwrite(label, cv::Mat(64, 128, CV_8UC3, cv::Scalar(200, 200, 200)));
  Scene scene = one_object("bottle", 0.28, 0.0);
  scene.objects[0].label.file = label;
  auto lying = [](World& world) {
    const ObjectState o = world.object(0);
    const Eigen::Quaterniond q(Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()) *
                               Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitY()));
    world.set_object_pose(0, Eigen::Vector3d(o.position.x(), o.position.y(), 0.035), q);
  };
  scene.render.shadows = false;
  World unshadowed(scene);
  lying(unshadowed);
  scene.render.shadows = true;
  World shadowed(scene);
  lying(shadowed);
  cv::Mat mask;
  shadowed.render_snapshot_surface(1, &mask);
  cv::Mat with, without;
  cv::cvtColor(shadowed.render_snapshot(1), with, cv::COLOR_BGR2GRAY);
  cv::cvtColor(unshadowed.render_snapshot(1), without, cv::COLOR_BGR2GRAY);
  // A dot: an object pixel the shadowed image draws much darker than both its neighbours along
  // the row, where the unshadowed image has no such dip (real shadow edges are long, not dots).
  int object = 0, dots = 0;
  for (int y = 0; y < mask.rows; ++y)
    for (int x = 2; x + 2 < mask.cols; ++x) {
      if (mask.at<uchar>(y, x) != 1) continue;
      ++object;
      auto dip = [&](const cv::Mat& g) {
        const int c = g.at<uchar>(y, x);
        return std::min(g.at<uchar>(y, x - 2), g.at<uchar>(y, x + 2)) - c;
      };
      dots += dip(with) > 25 && dip(without) < 10;
    }
  ASSERT_GT(object, 5000);
  EXPECT_LT(dots, 0.002 * object) << dots << " dotted pixels of " << object;
}

TEST(SimLabels, JpegLabelIsDrawnAndMasked) {
  const TempDir label_dir("label"), cache_dir("cache");
  const std::string& dir = label_dir.path;
  const std::string& cache = cache_dir.path;
  ::setenv("NUDGE_TEXTURE_CACHE", cache.c_str(), 1);
  Scene scene = one_object("bottle", 0.28, 0.0);
  scene.objects[0].appearance.colour = Eigen::Vector3d(0.2, 0.8, 0.2);
  const cv::Mat plain_mask = World(scene).render_mask(1);
  scene.objects[0].label.file = red_blue_jpeg(dir);
  // Turned so that the picture's seam (at the object's +x) faces away from the cameras, its
  // left (red) half is on the camera's left.
  scene.objects[0].yaw = M_PI;
  World world(scene);
  const cv::Mat image = world.render(1), mask = world.render_mask(1);
  ::unsetenv("NUDGE_TEXTURE_CACHE");
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir), {}), 1);  // only label.jpg
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(cache), {}), 1);  // its PNG
  // The label adds no pixels to the object's silhouette beyond its 0.4 mm, and loses none.
  const int plain = cv::countNonZero(plain_mask == 1), labelled = cv::countNonZero(mask == 1);
  EXPECT_NEAR(labelled, plain, 0.03 * plain);
  // Red on the left of the picture's middle (the surface point facing +x, towards the cameras),
  // blue on its right, green above the label.
  const CameraModel& cam = world.camera(1);
  const Eigen::Vector3d base = world.axis(0).base;
  int red = 0, blue = 0, green = 0;
  for (double z : {0.06, 0.075, 0.09}) {
    const Eigen::Vector2d centre = cam.project(base + Eigen::Vector3d(0.035, 0, z));
    for (int dx = -13; dx <= 13; dx += 2) {
      if (std::abs(dx) < 4) continue;
      const cv::Vec3b bgr = image.at<cv::Vec3b>(static_cast<int>(centre.y()), static_cast<int>(centre.x()) + dx);
      if (dx < 0 && bgr[2] > 2 * bgr[0] + 20 && bgr[2] > 2 * bgr[1]) ++red;
      if (dx > 0 && bgr[0] > 2 * bgr[2] + 20 && bgr[0] > 2 * bgr[1]) ++blue;
    }
  }
  const Eigen::Vector2d shoulder = cam.project(base + Eigen::Vector3d(0, 0, 0.14));
  const cv::Vec3b above = image.at<cv::Vec3b>(static_cast<int>(shoulder.y()), static_cast<int>(shoulder.x()));
  if (above[1] > above[0] + 30 && above[1] > above[2] + 30) ++green;
  EXPECT_GE(red, 13) << "of 15 samples";
  EXPECT_GE(blue, 13) << "of 15 samples";
  EXPECT_EQ(green, 1);
}

TEST(SimMeshes, ObjAndStlFilesLoad) {
  const TempDir temp("mesh");
  const std::string& dir = temp.path;
  const Mesh obj = read_mesh_file(box_obj(dir));
  EXPECT_EQ(obj.faces.size(), 12u);
  EXPECT_EQ(obj.texcoords.size(), obj.vertices.size());
  EXPECT_NEAR(std::fabs(obj.volume()), 40.0 * 100 * 60, 1e-3);
  const ObjectModel box = mesh_object(obj, 0.001, Eigen::Vector3d(M_PI / 2, 0, 0));  // Y up -> Z up
  EXPECT_EQ(box.kind, "mesh");
  EXPECT_NEAR(box.height, 0.100, 1e-6);
  EXPECT_NEAR(box.max_radius, std::hypot(0.02, 0.03), 1e-6);
  EXPECT_NEAR(box.parts[0].volume(), 0.04 * 0.1 * 0.06, 1e-9);  // faces outwards
  const Mesh stl = read_mesh_file(box_stl(dir));
  EXPECT_EQ(stl.vertices.size(), 8u);  // corners merged
  EXPECT_TRUE(stl.texcoords.empty());
  EXPECT_NEAR(stl.volume(), 0.04 * 0.1 * 0.06, 1e-9);
  // ASCII STL: one triangle of a tetrahedron per facet.
  const std::string ascii = dir + "/tetra.stl";
  std::ofstream(ascii) << "solid t\n"
                          "facet normal 0 0 0\nouter loop\nvertex 0 0 0\nvertex 0 1 0\nvertex 1 0 0\nendloop\nendfacet\n"
                          "facet normal 0 0 0\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 0 1\nendloop\nendfacet\n"
                          "facet normal 0 0 0\nouter loop\nvertex 0 0 0\nvertex 0 0 1\nvertex 0 1 0\nendloop\nendfacet\n"
                          "facet normal 0 0 0\nouter loop\nvertex 1 0 0\nvertex 0 1 0\nvertex 0 0 1\nendloop\nendfacet\n"
                          "endsolid t\n";
  EXPECT_NEAR(read_mesh_file(ascii).volume(), 1.0 / 6, 1e-6);
}

// A textured mesh object stands on the table at its pose, its mask and surface coordinates right.
TEST(SimMeshes, MeshObjectInASceneWithItsTextureAndTruth) {
  const TempDir temp("mesh_scene");
  const std::string& dir = temp.path;
  cv::imwrite(dir + "/texture.png", cv::Mat(32, 32, CV_8UC3, cv::Scalar(40, 40, 200)));
  box_obj(dir);
  const std::string path = dir + "/scene.yaml";
  std::ofstream(path) << "%YAML:1.0\nobjects:\n"
                         "  - { kind: mesh, name: box, position: [0.26, 0.02], yaw_deg: 30,\n"
                         "      mesh: { file: box.obj, texture: texture.png, scale: 0.001, rotation_deg: [90, 0, 0] } }\n";
  World world(load_scene(path));
  const ObjectState box = world.object(0);
  EXPECT_EQ(box.kind, "mesh");
  EXPECT_NEAR(box.height, 0.1, 1e-6);
  EXPECT_NEAR(box.position.z(), 0.0, 0.002);
  EXPECT_LT(box.tilt(), 1 * kDeg);
  cv::Mat mask;
  const cv::Mat surface = world.render_surface(1, &mask);
  const cv::Mat image = world.render(1);
  int pixels = 0, on_surface = 0, textured = 0;
  for (int y = 0; y < mask.rows; ++y)
    for (int x = 0; x < mask.cols; ++x) {
      if (mask.at<uchar>(y, x) != 1) continue;
      ++pixels;
      const cv::Vec3f p = surface.at<cv::Vec3f>(y, x);
      // On one of the box's faces: |x| = 20 mm, |y| = 30 mm or z = 100 mm (within 2 mm).
      if ((std::fabs(std::fabs(p[0]) - 0.02) < 0.002 && std::fabs(p[1]) < 0.032) ||
          (std::fabs(std::fabs(p[1]) - 0.03) < 0.002 && std::fabs(p[0]) < 0.022) || std::fabs(p[2] - 0.1) < 0.002)
        ++on_surface;
      const cv::Vec3b bgr = image.at<cv::Vec3b>(y, x);
      if (bgr[2] > bgr[0] + 40) ++textured;
    }
  EXPECT_GT(pixels, 2000);
  EXPECT_GT(on_surface, 0.97 * pixels);
  EXPECT_GT(textured, 0.9 * pixels);
  // No object, no coordinates.
  EXPECT_TRUE(std::isnan(surface.at<cv::Vec3f>(0, 0)[0]));
}

// Each surface pixel of a bottle lies on the bottle: its radius is the profile's at its height.
TEST(SimMeshes, SurfaceCoordinatesLieOnTheBottle) {
  World world(one_object("bottle", 0.27, -0.03));
  const ObjectModel bottle = make_object("bottle");
  cv::Mat mask;
  const cv::Mat surface = world.render_surface(0, &mask);
  int pixels = 0, near = 0;
  for (int y = 0; y < mask.rows; ++y)
    for (int x = 0; x < mask.cols; ++x) {
      if (mask.at<uchar>(y, x) != 1) continue;
      ++pixels;
      const cv::Vec3f p = surface.at<cv::Vec3f>(y, x);
      const double r = std::hypot(p[0], p[1]);
      if (p[2] > 0.005 && p[2] < 0.195 && std::fabs(r - bottle.radius_at(p[2])) < 0.0015) ++near;
      else if (p[2] >= 0.195 || p[2] <= 0.005) ++near;  // the cap and the base: flat
    }
  EXPECT_GT(pixels, 3000);
  EXPECT_GT(near, 0.97 * pixels);
}

TEST(SimMeshes, BadInputNamesTheFileAndTheField) {
  const TempDir temp("bad");
  const std::string& dir = temp.path;
  box_obj(dir);
  std::ofstream(dir + "/not_an_image.png") << "this is text, not a picture\n";
  std::ofstream(dir + "/bad_index.obj") << "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n";
  std::ofstream(dir + "/flat.obj") << "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  std::ofstream(dir + "/garbage.stl") << "not an stl at all";
  std::ofstream(dir + "/shape.ply") << "ply\n";
  auto error = [&](const std::string& object) {
    std::string path;
    const std::string msg = load_error("%YAML:1.0\nobjects:\n  - " + object + "\n", &path);
    EXPECT_NE(msg.find(path), std::string::npos) << "the scene file is not named: " << msg;
    return msg;
  };
  auto expect = [](const std::string& msg, const std::vector<std::string>& parts) {
    for (const auto& p : parts) EXPECT_NE(msg.find(p), std::string::npos) << "'" << p << "' missing in: " << msg;
  };
  // A missing label picture, a label that is not a picture, a label on a kind without one.
  expect(error("{ kind: bottle, position: [0.25, 0], label: " + dir + "/missing.jpg }"),
         {"objects[0].label.file", dir + "/missing.jpg"});
  expect(error("{ kind: bottle, position: [0.25, 0], label: { file: " + dir + "/not_an_image.png } }"),
         {"objects[0].label.file", "not_an_image.png", "not a picture"});
  expect(error("{ kind: marker, position: [0.25, 0], label: " + dir + "/not_an_image.png }"), {"objects[0].label"});
  expect(error("{ kind: bottle, position: [0.25, 0], label: { file: " + dir + "/box.obj, top: 0.5 } }"),
         {"objects[0].label.file", "not a picture"});
  cv::imwrite(dir + "/label.png", cv::Mat(8, 8, CV_8UC3, cv::Scalar(0, 0, 255)));
  expect(error("{ kind: can, position: [0.25, 0], label: { file: " + dir + "/label.png, top: 0.5 } }"),
         {"objects[0].label", "within the object's height"});
  expect(error("{ kind: can, position: [0.25, 0], label: { file: " + dir + "/label.png, size: 2 } }"),
         {"objects[0].label.size: unknown field"});
  // An unknown kind; a mesh object without a file, with a missing file, with files that do not load.
  expect(error("{ kind: teapot, position: [0.25, 0] }"), {"objects[0].kind", "teapot", "mesh"});
  expect(error("{ kind: mesh, position: [0.25, 0] }"), {"objects[0].mesh.file", "needs a mesh file"});
  expect(error("{ kind: mesh, position: [0.25, 0], mesh: { file: " + dir + "/nothere.obj } }"),
         {"objects[0].mesh.file", "nothere.obj"});
  expect(error("{ kind: mesh, position: [0.25, 0], mesh: { file: " + dir + "/bad_index.obj } }"),
         {"objects[0].mesh.file", "bad_index.obj", "line 4", "out of range"});
  expect(error("{ kind: mesh, position: [0.25, 0], mesh: { file: " + dir + "/flat.obj } }"),
         {"objects[0].mesh.file", "flat.obj", "no volume"});
  expect(error("{ kind: mesh, position: [0.25, 0], mesh: { file: " + dir + "/garbage.stl } }"),
         {"objects[0].mesh.file", "garbage.stl"});
  expect(error("{ kind: mesh, position: [0.25, 0], mesh: { file: " + dir + "/shape.ply } }"),
         {"objects[0].mesh.file", "shape.ply", ".obj or .stl"});
  // A mesh texture that is not a picture; a bad scale; mesh fields on a bottle; a typo.
  expect(error("{ kind: mesh, position: [0.25, 0], mesh: { file: " + dir + "/box.obj, scale: 0.001, texture: " +
               dir + "/not_an_image.png } }"),
         {"objects[0].mesh.texture", "not_an_image.png", "not a picture"});
  expect(error("{ kind: mesh, position: [0.25, 0], mesh: { file: " + dir + "/box.obj, scale: -1 } }"),
         {"objects[0].mesh.scale"});
  expect(error("{ kind: bottle, position: [0.25, 0], mesh: { file: " + dir + "/box.obj } }"), {"objects[0].mesh"});
  expect(error("{ kind: mesh, position: [0.25, 0], mesh: { file: " + dir + "/box.obj, scael: 2 } }"),
         {"objects[0].mesh.scael: unknown field"});
  // A scene built in code: the texture is checked when the world is built, too.
  Scene scene = one_object("can");
  scene.objects[0].appearance.kind = Appearance::Kind::Image;
  scene.objects[0].appearance.file = dir + "/not_an_image.png";
  expect(scene_error(scene), {"objects[0].file", "not a picture"});
}

TEST(SimMeshes, SurfaceCoordinatesSurviveAPngRoundTrip) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  cv::Mat points(2, 2, CV_32FC3, cv::Scalar(nan, nan, nan));
  points.at<cv::Vec3f>(0, 1) = cv::Vec3f(0.0123f, -0.0345f, 0.199f);
  points.at<cv::Vec3f>(1, 0) = cv::Vec3f(-0.5f, 0.5f, 0.0f);
  const TempDir temp("surface");
  const std::string path = temp.path + "/surface.png";
  ASSERT_TRUE(cv::imwrite(path, encode_surface(points)));
  const cv::Mat back = decode_surface(cv::imread(path, cv::IMREAD_UNCHANGED));
  ASSERT_EQ(back.type(), CV_32FC3);
  EXPECT_TRUE(std::isnan(back.at<cv::Vec3f>(0, 0)[0]));
  EXPECT_TRUE(std::isnan(back.at<cv::Vec3f>(1, 1)[2]));
  for (const cv::Point at : {cv::Point(1, 0), cv::Point(0, 1)})
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(back.at<cv::Vec3f>(at)[k], points.at<cv::Vec3f>(at)[k], 1e-5);
  EXPECT_THROW(decode_surface(cv::Mat(2, 2, CV_8UC3)), std::invalid_argument);
}

// The learning experiment's seven training scenes: one labelled bottle each, in the workspace.
TEST(SimLabels, TrainingScenesOfTheLearningExperimentLoad) {
  const std::string dir = std::string(NUDGE_SOURCE_DIR) + "/experiments/scenes/learning";
  int scenes = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.path().extension() != ".yaml") continue;
    SCOPED_TRACE(entry.path().string());
    const Scene scene = load_scene(entry.path().string());
    ++scenes;
    ASSERT_EQ(scene.objects.size(), 1u);
    EXPECT_EQ(scene.objects[0].kind, "bottle");
    EXPECT_TRUE(scene.objects[0].label.present());
    EXPECT_TRUE(scene.arm.present);
  }
  EXPECT_EQ(scenes, 7);
}

// The shipped carton (an OBJ, Y up, millimetres) with a four-colour picture: each visible pixel
// shows the colour of the quadrant of the picture its surface point maps to, so the file's
// texture coordinates are used the right way up and the right way round.
TEST(SimMeshes, ObjTextureIsMappedTheRightWayRound) {
  const TempDir temp("carton");
  const std::string& dir = temp.path;
  cv::Mat picture(64, 64, CV_8UC3);
  picture(cv::Rect(0, 0, 32, 32)).setTo(cv::Scalar(0, 0, 255));     // top left: red
  picture(cv::Rect(32, 0, 32, 32)).setTo(cv::Scalar(0, 255, 0));    // top right: green
  picture(cv::Rect(0, 32, 32, 32)).setTo(cv::Scalar(255, 0, 0));    // bottom left: blue
  picture(cv::Rect(32, 32, 32, 32)).setTo(cv::Scalar(0, 255, 255));  // bottom right: yellow
  cv::imwrite(dir + "/quadrants.png", picture);
  Scene scene = default_scene();
  ObjectSpec carton;
  carton.kind = "mesh";
  carton.position = Eigen::Vector2d(0.25, 0.0);
  carton.yaw = 200 * kDeg;  // faces u in [0.25, 0.75] towards the cameras
  carton.mesh.file = std::string(NUDGE_SOURCE_DIR) + "/experiments/scenes/learning/meshes/carton.obj";
  carton.mesh.texture = dir + "/quadrants.png";
  carton.mesh.scale = 0.001;
  carton.mesh.rotation = Eigen::Vector3d(M_PI / 2, 0, 0);
  scene.objects.push_back(carton);
  World world(scene);
  EXPECT_NEAR(world.object(0).height, 0.19, 1e-6);
  cv::Mat mask;
  const cv::Mat surface = world.render_surface(1, &mask);
  const cv::Mat image = world.render(1);
  int sides = 0, right = 0;
  for (int y = 0; y < mask.rows; ++y)
    for (int x = 0; x < mask.cols; ++x) {
      if (mask.at<uchar>(y, x) != 1) continue;
      const cv::Vec3f p = surface.at<cv::Vec3f>(y, x);
      if (p[2] > 0.188 || std::fabs(p[2] - 0.095) < 0.01) continue;  // the top; the picture's middle row
      // u runs once round: from the corner (-35, 35) mm via (-35, -35), (35, -35), (35, 35).
      double u;
      if (std::fabs(p[0] + 0.035) < 0.002) u = 0.25 * (0.035 - p[1]) / 0.07;
      else if (std::fabs(p[1] + 0.035) < 0.002) u = 0.25 + 0.25 * (p[0] + 0.035) / 0.07;
      else if (std::fabs(p[0] - 0.035) < 0.002) u = 0.5 + 0.25 * (p[1] + 0.035) / 0.07;
      else if (std::fabs(p[1] - 0.035) < 0.002) u = 0.75 + 0.25 * (0.035 - p[0]) / 0.07;
      else continue;
      if (std::fabs(u - 0.5) < 0.02 || u < 0.02 || u > 0.98) continue;  // the picture's middle column, seam
      ++sides;
      const bool top = p[2] > 0.095, left = u < 0.5;
      const cv::Vec3b c = image.at<cv::Vec3b>(y, x);
      const int b = c[0], g = c[1], r = c[2];
      const bool ok = top ? (left ? r > g + 40 && r > b + 40 : g > r + 40 && g > b + 40)
                          : (left ? b > r + 40 && b > g + 40 : r > b + 40 && g > b + 40);
      if (ok) ++right;
    }
  EXPECT_GT(sides, 1500);
  EXPECT_GT(right, 0.95 * sides);
}
