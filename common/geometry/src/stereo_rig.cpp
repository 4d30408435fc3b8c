#include "nudge/geometry/stereo_rig.hpp"

#include <Eigen/Core>
#include <Eigen/LU>  // determinant
#include <opencv2/core.hpp>
#include <opencv2/core/eigen.hpp>  // after Eigen/Core, as OpenCV requires

#include <cmath>
#include <optional>
#include <stdexcept>

#include "nudge/atomic_file.hpp"
#include "nudge/yaml_file.hpp"

namespace nudge::geometry {

// ---------------------------------------------------------------------------------------------
// Lens model

Eigen::Vector2d Camera::distort(const Eigen::Vector2d& n) const {
  const auto [k1, k2, p1, p2, k3] = distortion;
  const double x = n.x(), y = n.y();
  const double r2 = x * x + y * y;
  const double radial = 1 + r2 * (k1 + r2 * (k2 + r2 * k3));
  return {x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x),
          y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y};
}

Eigen::Vector2d Camera::project(const Eigen::Vector3d& p) const {
  const Eigen::Vector2d d = distort(p.head<2>() / p.z());
  return {K(0, 0) * d.x() + K(0, 1) * d.y() + K(0, 2), K(1, 1) * d.y() + K(1, 2)};
}

Outcome<Eigen::Vector2d> Camera::normalise(const Eigen::Vector2d& pixel) const {
  // Remove the pixel offset, focal length and skew: distorted normalised coordinates.
  const double yd = (pixel.y() - K(1, 2)) / K(1, 1);
  const double xd = (pixel.x() - K(0, 2) - K(0, 1) * yd) / K(0, 0);
  const auto [k1, k2, p1, p2, k3] = distortion;
  // comp_distortion_oulu: x <- (xd - tangential(x)) / radial(x). Bouguet runs 20 iterations; we
  // run until the step is negligible, since strong distortion near the border converges slowly.
  constexpr int kMaxIterations = 200;
  constexpr double kTolerance = 1e-14;
  double x = xd, y = yd;
  for (int i = 0; i < kMaxIterations; ++i) {
    const double r2 = x * x + y * y;
    const double radial = 1 + r2 * (k1 + r2 * (k2 + r2 * k3));
    if (!(radial > 0.05)) return Outcome<Eigen::Vector2d>::failure("lens model folds over at this pixel");
    const double dx = 2 * p1 * x * y + p2 * (r2 + 2 * x * x);
    const double dy = p1 * (r2 + 2 * y * y) + 2 * p2 * x * y;
    const double nx = (xd - dx) / radial, ny = (yd - dy) / radial;
    const double step = std::hypot(nx - x, ny - y);
    x = nx;
    y = ny;
    if (!std::isfinite(x) || !std::isfinite(y)) break;
    if (step < kTolerance) return Outcome<Eigen::Vector2d>::success({x, y});
  }
  // Accept the last iterate only if it reproduces the pixel (slow but genuine convergence).
  if (std::isfinite(x) && std::isfinite(y) && (distort({x, y}) - Eigen::Vector2d(xd, yd)).norm() < 1e-9)
    return Outcome<Eigen::Vector2d>::success({x, y});
  return Outcome<Eigen::Vector2d>::failure("undistortion did not converge at pixel (" +
                                           std::to_string(pixel.x()) + ", " + std::to_string(pixel.y()) + ")");
}

// ---------------------------------------------------------------------------------------------
// Validation

namespace {

void require(bool ok, const std::string& message) {
  if (!ok) throw std::invalid_argument(message);
}

void validate_camera(const Camera& c, const std::string& side) {
  require(c.width > 0 && c.height > 0, side + ".image_width/image_height must be positive");
  require(c.K.allFinite(), side + ".camera_matrix must be finite");
  require(c.K(0, 0) > 0 && c.K(1, 1) > 0, side + ".camera_matrix focal lengths must be positive");
  require(c.K(1, 0) == 0 && c.K(2, 0) == 0 && c.K(2, 1) == 0 && c.K(2, 2) == 1,
          side + ".camera_matrix must be upper triangular with K(2,2) = 1");
  for (double k : c.distortion) require(std::isfinite(k), side + ".distortion_coefficients must be finite");
}

}  // namespace

void validate(const StereoRig& rig) {
  validate_camera(rig.left, "left");
  validate_camera(rig.right, "right");
  require(rig.R.allFinite() && rig.T.allFinite(), "R and T must be finite");
  require((rig.R * rig.R.transpose() - Eigen::Matrix3d::Identity()).norm() < 1e-6 && rig.R.determinant() > 0,
          "R must be a rotation matrix");
}

// ---------------------------------------------------------------------------------------------
// YAML

namespace {

struct Reader {
  const YAML::Node& root;
  const std::string& path;

  [[noreturn]] void fail(const std::string& field, const std::string& what) const {
    throw std::runtime_error(path + ": field '" + field + "' " + what);
  }
  YAML::Node node(const std::string& field) const {
    const auto dot = field.find('.');
    std::optional<YAML::Node> n;
    if (dot == std::string::npos) {
      n = yaml_field(root, field);
    } else if (const auto parent = yaml_field(root, field.substr(0, dot))) {
      n = yaml_field(*parent, field.substr(dot + 1));
    }
    if (!n) fail(field, "is missing");
    return *n;
  }
  int integer(const std::string& field) const {
    const auto value = yaml_int(node(field));
    if (!value) fail(field, "must be an integer");
    return *value;
  }
  std::pair<int, int> matrix_size(const std::string& field, const YAML::Node& n) const {
    const auto rows_node = yaml_field(n, "rows"), cols_node = yaml_field(n, "cols");
    const auto rows = rows_node ? yaml_int(*rows_node) : std::nullopt;
    const auto cols = cols_node ? yaml_int(*cols_node) : std::nullopt;
    if (!rows || !cols) fail(field, "is not an OpenCV matrix (rows, cols, dt, data)");
    // A rig's matrices are at most 3x3 or 1x5; a bound keeps a file declaring 100000 columns
    // (found by fuzz_calibration when OpenCV read these files) from costing gigabytes.
    constexpr int kMaxSide = 16;
    const int r = *rows, c = *cols;
    if (r < 1 || r > kMaxSide || c < 1 || c > kMaxSide)
      fail(field, "declares " + std::to_string(r) + "x" + std::to_string(c) + " elements (at most " +
                      std::to_string(kMaxSide) + " a side)");
    return {r, c};
  }
  // An OpenCV matrix (`!!opencv-matrix` rows, cols, dt, data) of one channel, as doubles.
  cv::Mat matrix(const std::string& field) const {
    const YAML::Node n = node(field);
    const auto [rows, cols] = matrix_size(field, n);
    const auto type = yaml_field(n, "dt");
    const auto type_name = type ? yaml_text(*type) : std::nullopt;
    if (!type_name || type_name->size() != 1 || std::string("ucwsifd").find(*type_name) == std::string::npos)
      fail(field + ".dt", "must be one of OpenCV's one-channel types u, c, w, s, i, f, d");
    const auto data = yaml_field(n, "data");
    const int count = rows * cols;
    const std::string expected = "must be a list of " + std::to_string(count) + " numbers (rows x cols)";
    if (!data || !data->IsSequence() || data->size() != static_cast<size_t>(count)) fail(field + ".data", expected);
    cv::Mat m(rows, cols, CV_64F);
    int i = 0;
    for (const YAML::Node& item : *data) {
      const auto value = yaml_number(item);
      if (!value) fail(field + ".data", expected);
      m.at<double>(i / cols, i % cols) = *value;
      ++i;
    }
    return m;
  }
};

Camera read_camera(const Reader& in, const std::string& side) {
  Camera c;
  c.width = in.integer(side + ".image_width");
  c.height = in.integer(side + ".image_height");
  const cv::Mat K = in.matrix(side + ".camera_matrix");
  if (K.rows != 3 || K.cols != 3) in.fail(side + ".camera_matrix", "must be 3x3");
  cv::cv2eigen(K, c.K);
  const std::string dist_field = side + ".distortion_coefficients";
  const cv::Mat dist = in.matrix(dist_field);
  if (dist.total() != 4 && dist.total() != 5) in.fail(dist_field, "must hold 4 or 5 values (k1 k2 p1 p2 [k3])");
  for (size_t i = 0; i < dist.total(); ++i) c.distortion[i] = dist.at<double>(static_cast<int>(i));
  return c;
}

void write_camera(cv::FileStorage& fs, const Camera& c, const std::string& side) {
  cv::Mat K;
  cv::eigen2cv(c.K, K);
  fs << side << "{";
  fs << "image_width" << c.width << "image_height" << c.height;
  fs << "camera_matrix" << K;
  fs << "distortion_coefficients" << cv::Mat(1, 5, CV_64F, const_cast<double*>(c.distortion.data())).clone();
  fs << "}";
}

}  // namespace

StereoRig load_rig(const std::string& path) {
  const YAML::Node root = read_yaml_file(path, "stereo rig");
  const Reader in{root, path};
  StereoRig rig;
  rig.left = read_camera(in, "left");
  rig.right = read_camera(in, "right");
  const cv::Mat R = in.matrix("R"), T = in.matrix("T");
  if (R.rows != 3 || R.cols != 3) in.fail("R", "must be 3x3");
  if (T.total() != 3) in.fail("T", "must hold 3 values");
  cv::cv2eigen(R, rig.R);
  for (int i = 0; i < 3; ++i) rig.T(i) = T.at<double>(i);
  try {
    validate(rig);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(path + ": " + e.what());
  }
  return rig;
}

void save_rig(const StereoRig& rig, const std::string& path) {
  validate(rig);
  cv::FileStorage fs(".yaml", cv::FileStorage::WRITE | cv::FileStorage::MEMORY | cv::FileStorage::FORMAT_YAML);
  write_camera(fs, rig.left, "left");
  write_camera(fs, rig.right, "right");
  cv::Mat R, T;
  cv::eigen2cv(rig.R, R);
  cv::eigen2cv(rig.T, T);
  fs << "R" << R << "T" << T;
  write_file_atomically(path, fs.releaseAndGetString());
}

}  // namespace nudge::geometry
