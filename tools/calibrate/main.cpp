// nudge-calibrate: stereo calibration from chessboard image pairs (thesis sec. 4.3.2 used Bouguet's
// toolbox; this is OpenCV's equivalent). Writes the rig file the triangulation service loads and
// prints the stereo RMS reprojection error on its last line as `rms_px=<value>`.
//   nudge-calibrate --board 9x6 --square 0.025 --left 'left*.jpg' --right 'right*.jpg' --out rig.yaml
#include <glob.h>

#include <Eigen/Core>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>  // after Eigen, as OpenCV requires
#include <opencv2/core/utils/logger.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <iostream>
#include <map>
#include <stdexcept>

#include "nudge/camera/image_file.hpp"
#include "nudge/flags.hpp"
#include "nudge/geometry/stereo_rig.hpp"
#include "nudge/geometry/workspace.hpp"
#include "nudge/log.hpp"
#include "nudge/progress.hpp"

using namespace nudge;

namespace {

struct Options {
  std::string board, left_glob, right_glob, out, table_left, table_right;
  double square = 0;
};

struct BoardSize {
  int columns = 0, rows = 0;  // inner corners
};

// Sorted file names matching a shell pattern; an error if nothing matches.
std::vector<std::string> expand(const std::string& pattern, const std::string& flag) {
  glob_t found{};
  const int rc = ::glob(pattern.c_str(), 0, nullptr, &found);
  std::vector<std::string> files(found.gl_pathv, found.gl_pathv + (rc == 0 ? found.gl_pathc : 0));
  globfree(&found);
  if (files.empty()) throw std::runtime_error("--" + flag + " '" + pattern + "' matches no files");
  return files;  // glob(3) sorts
}

BoardSize parse_board(const std::string& text) {
  const auto x = text.find('x');
  if (x == std::string::npos) throw FlagError("--board must be COLSxROWS (inner corners), e.g. 9x6");
  BoardSize b{parse_int(text.substr(0, x), "--board columns"), parse_int(text.substr(x + 1), "--board rows")};
  if (b.columns < 2 || b.rows < 2) throw FlagError("--board needs at least 2x2 inner corners");
  return b;
}

cv::Mat read_grey(const std::string& path) {
  return camera::read_image_file(path, cv::IMREAD_GRAYSCALE);  // throws naming the file
}

// Inner corners to sub-pixel precision, or empty when the board is not (fully) visible. The
// sector-based detector is slower than findChessboardCorners + cornerSubPix but halves the
// reprojection error on the opencv-doc pairs (0.25 against 0.44 px).
std::vector<cv::Point2f> find_corners(const cv::Mat& grey, const BoardSize& board) {
  std::vector<cv::Point2f> corners;
  const cv::Size size(board.columns, board.rows);
  if (!cv::findChessboardCornersSB(grey, size, corners, cv::CALIB_CB_ACCURACY)) return {};
  return corners;
}

struct Views {
  cv::Size left_size, right_size;
  std::vector<std::vector<cv::Point2f>> left, right;  // one entry per usable pair
};

// The size most of a camera's images share (the earliest of equally common ones): a glob that
// also matches an image of another size (opencv-doc's left.jpg) should lose that image, not the run.
cv::Size common_size(const std::vector<cv::Mat>& images) {
  std::map<std::pair<int, int>, int> count;
  for (const auto& image : images) ++count[{image.cols, image.rows}];
  cv::Size best;
  int best_count = 0;
  for (const auto& image : images) {
    const int n = count[{image.cols, image.rows}];
    if (n > best_count) {
      best_count = n;
      best = image.size();
    }
  }
  return best;
}

std::string size_text(cv::Size size) { return std::to_string(size.width) + "x" + std::to_string(size.height); }

Views collect_views(const std::vector<std::string>& left, const std::vector<std::string>& right,
                    const BoardSize& board, Progress& progress) {
  if (left.size() != right.size())
    throw std::runtime_error("--left matches " + std::to_string(left.size()) + " files but --right matches " +
                             std::to_string(right.size()) + "; images pair up in sorted order");
  std::vector<cv::Mat> left_images, right_images;
  for (size_t i = 0; i < left.size(); ++i) {
    progress.step("reading pair " + std::to_string(i + 1));
    left_images.push_back(read_grey(left[i]));
    right_images.push_back(read_grey(right[i]));
  }
  Views views;
  views.left_size = common_size(left_images);
  views.right_size = common_size(right_images);
  for (size_t i = 0; i < left.size(); ++i) {
    progress.step("board corners, pair " + std::to_string(i + 1));
    const cv::Mat &l = left_images[i], &r = right_images[i];
    const bool left_odd = l.size() != views.left_size, right_odd = r.size() != views.right_size;
    if (left_odd || right_odd) {
      const std::string& path = left_odd ? left[i] : right[i];
      const cv::Size size = left_odd ? l.size() : r.size(), usual = left_odd ? views.left_size : views.right_size;
      progress.clear_status();
      log::warn() << path << ": image size " << size_text(size) << " differs from the " << size_text(usual) << " of most "
                  << (left_odd ? "left" : "right") << " images; pair " << i + 1 << " skipped";
      continue;
    }
    auto lc = find_corners(l, board), rc = find_corners(r, board);
    if (lc.empty() || rc.empty()) {
      const char* where = lc.empty() && rc.empty() ? "either image" : lc.empty() ? "the left image" : "the right image";
      progress.clear_status();
      log::warn() << "pair " << i + 1 << " (" << left[i] << ", " << right[i] << "): no " << board.columns << "x"
                  << board.rows << " board found in " << where << "; pair skipped";
      continue;
    }
    views.left.push_back(std::move(lc));
    views.right.push_back(std::move(rc));
  }
  // Three views constrain the intrinsics; fewer leave the calibration degenerate.
  if (views.left.size() < 3)
    throw std::runtime_error("the board was found in only " + std::to_string(views.left.size()) + " of " +
                             std::to_string(left.size()) + " pairs; at least 3 are needed");
  return views;
}

std::vector<cv::Point3f> board_points(const BoardSize& board, double square) {
  std::vector<cv::Point3f> points;
  for (int r = 0; r < board.rows; ++r)
    for (int c = 0; c < board.columns; ++c)
      points.emplace_back(static_cast<float>(c * square), static_cast<float>(r * square), 0.f);
  return points;
}

geometry::Camera to_camera(const cv::Mat& K, const cv::Mat& distortion, cv::Size size) {
  geometry::Camera camera;
  camera.width = size.width;
  camera.height = size.height;
  cv::cv2eigen(K, camera.K);
  for (int i = 0; i < 5; ++i) camera.distortion[i] = distortion.at<double>(i);
  return camera;
}

struct Calibration {
  geometry::StereoRig rig;
  double rms = 0;  // px, over both images of every pair
};

// Each camera alone first (a good start), then both together refining everything.
Calibration calibrate(const Views& views, const BoardSize& board, double square) {
  const std::vector<std::vector<cv::Point3f>> objects(views.left.size(), board_points(board, square));
  cv::Mat K_left, K_right, d_left, d_right, R, T, E, F;
  std::vector<cv::Mat> rvecs, tvecs;
  const double rms_left = cv::calibrateCamera(objects, views.left, views.left_size, K_left, d_left, rvecs, tvecs);
  const double rms_right = cv::calibrateCamera(objects, views.right, views.right_size, K_right, d_right, rvecs, tvecs);
  log::info() << "single-camera RMS: left " << rms_left << " px, right " << rms_right << " px";
  // stereoCalibrate takes one image size (used only for initialisation, not with intrinsic guesses).
  const double rms = cv::stereoCalibrate(
      objects, views.left, views.right, K_left, d_left, K_right, d_right, views.left_size, R, T, E, F,
      cv::CALIB_USE_INTRINSIC_GUESS,
      cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 100, 1e-6));
  Calibration result;
  result.rms = rms;
  result.rig.left = to_camera(K_left, d_left, views.left_size);
  result.rig.right = to_camera(K_right, d_right, views.right_size);
  cv::cv2eigen(R, result.rig.R);
  cv::cv2eigen(T, result.rig.T);
  return result;
}

std::vector<Eigen::Vector2d> to_eigen(const std::vector<cv::Point2f>& points) {
  std::vector<Eigen::Vector2d> out;
  for (const auto& p : points) out.emplace_back(p.x, p.y);
  return out;
}

// The table plane from one pair showing the board lying on the table (thesis sec. 4.3.5).
geometry::Plane table_plane(const geometry::StereoRig& rig, const Options& opt, const BoardSize& board) {
  const cv::Mat left = read_grey(opt.table_left), right = read_grey(opt.table_right);
  const auto left_corners = find_corners(left, board), right_corners = find_corners(right, board);
  if (left_corners.empty() || right_corners.empty())
    throw std::runtime_error("table pair (" + opt.table_left + ", " + opt.table_right + "): no board found in " +
                             (left_corners.empty() ? opt.table_left : opt.table_right));
  const auto plane = geometry::table_from_corners(rig, to_eigen(left_corners), to_eigen(right_corners));
  if (!plane) throw std::runtime_error("table pair: " + plane.reason());
  log::info() << "table plane: normal (" << plane->normal.transpose() << "), " << plane->offset
              << " m from the right camera, rms residual " << plane->rms_residual * 1000 << " mm";
  return *plane;
}

}  // namespace

int main(int argc, char** argv) {
  log::set_component("calibrate");
  cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_SILENT);  // we report bad files ourselves
  Options opt;
  Flags flags("nudge-calibrate",
              "Stereo calibration from chessboard image pairs (OpenCV). Left and right images pair up in\n"
              "sorted order; pairs where either image lacks the board are skipped with a warning.\n"
              "Writes the rig file (both intrinsics with distortion k1 k2 p1 p2 k3, R, T, image sizes;\n"
              "x_right = R x_left + T, metres) and prints `rms_px=<value>` on the last line.\n"
              "With --table-left/--table-right (the board lying on the table) it also writes table_plane,\n"
              "fitted to the triangulated corners, in the right camera's frame.");
  flags.add_string("board", &opt.board, "inner corners COLSxROWS, e.g. 9x6");
  flags.add_double("square", &opt.square, "side of a chessboard square, metres");
  flags.add_string("left", &opt.left_glob, "left images, a shell pattern (quote it)");
  flags.add_string("right", &opt.right_glob, "right images, a shell pattern (quote it)");
  flags.add_string("out", &opt.out, "calibration file to write (YAML)");
  flags.add_string("table-left", &opt.table_left, "left image of the board lying on the table: adds table_plane");
  flags.add_string("table-right", &opt.table_right, "right image of the same board (with --table-left)");
  BoardSize board;
  try {
    if (!flags.parse(argc, argv)) return 0;
    for (const char* name : {"board", "square", "left", "right", "out"})
      if (!flags.given(name)) throw FlagError(std::string("--") + name + " is required");
    board = parse_board(opt.board);
    if (!(opt.square > 0)) throw FlagError("--square must be a positive length in metres");
    if (opt.table_left.empty() != opt.table_right.empty())
      throw FlagError("--table-left and --table-right go together");
  } catch (const std::exception& e) {
    std::cerr << "nudge-calibrate: " << e.what() << "\n";
    return 2;
  }
  try {
    const std::vector<std::string> left = expand(opt.left_glob, "left"), right = expand(opt.right_glob, "right");
    // Steps: reading each pair, finding its corners, then the calibration itself.
    Progress progress("nudge-calibrate", static_cast<int>(2 * left.size() + 1));
    const Views views = collect_views(left, right, board, progress);
    progress.step("stereo calibration of " + std::to_string(views.left.size()) + " pairs");
    const Calibration calibration = calibrate(views, board, opt.square);
    progress.finish(std::to_string(views.left.size()) + " of " + std::to_string(left.size()) + " pairs used, rms " +
                    std::to_string(calibration.rms) + " px");
    geometry::Workspace workspace;
    if (!opt.table_left.empty()) workspace.table = table_plane(calibration.rig, opt, board);
    geometry::save_rig(calibration.rig, workspace, opt.out);
    log::info() << "wrote " << opt.out << " from " << views.left.size() << " pairs; baseline "
                << calibration.rig.T.norm() << " m";
    std::cout << "rms_px=" << calibration.rms << std::endl;
  } catch (const std::exception& e) {
    log::error() << e.what();
    return 1;
  }
  return 0;
}
