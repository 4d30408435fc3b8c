// Camera-arm calibration in simulation (thesis App. B): the arm marks points known in its own
// frame, a checkerboard lies on the table with its corners on those points, the stereo pair
// triangulates the corners, and absolute orientation by SVD (Arun, Huang & Blostein 1987) gives
// the transform between the arm's frame and the cameras'. The table plane comes from the same
// corners (sec. 4.3.5). The simulator knows the truth, so the errors can be measured.
//   nudge-exp-calibration-sim [--stills] [--noise SIGMA] [--keep DIR] [--max-translation-mm 2 --max-rotation-deg 0.5]
// The board is printed into the table's texture at a known place for each of several poses; the
// arm's frame is the world frame of docs/sim.md (origin on the arm base axis at table height).
// The stereo rig itself (intrinsics, left-right extrinsics) is the simulator's, as a calibrated rig
// would be (nudge-calibrate does that part from board images).
// Writes the calibration file docs/results/calibration_sim.yaml (the nudge_geometry rig, its
// table_plane and arm_base, and the arm -> right camera transform) and
// docs/results/calibration_sim.{json,md} (translation_error_mm, rotation_error_deg, ...).
// Results are outputs: the demo and the services read config/calibration_sim.yaml, a copy of it.
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <iostream>
#include <sstream>

#include "nudge/atomic_file.hpp"
#include "nudge/flags.hpp"
#include "nudge/geometry/absolute_orientation.hpp"
#include "nudge/geometry/stereo_rig.hpp"
#include "nudge/geometry/workspace.hpp"
#include "nudge/json.hpp"
#include "nudge/progress.hpp"
#include "nudge/sim/world.hpp"
#include "report.hpp"

using namespace nudge;
using namespace nudge::experiments;
namespace geo = nudge::geometry;

namespace {

constexpr double kDeg = M_PI / 180.0;
// The table texture: one texel per millimetre over the drawn table. MuJoCo maps an image with
// texrepeat 1 (texuniform off) onto the table plane with column 0 at x = kTableXMin and row 0 at
// y = +kTableHalfY (rows run towards -y); texel edges fall on whole millimetres.
constexpr double kTexel = 0.001;
constexpr int kTextureWidth = 1700;   // (kTableXMax - kTableXMin) / kTexel
constexpr int kTextureHeight = 2000;  // 2 kTableHalfY / kTexel
// The board: 8 x 5 inner corners, 25 mm squares, its long side along the world y axis.
constexpr int kCornersAlongY = 8, kCornersAlongX = 5, kSquareTexels = 25;

int texel_column(double x) { return static_cast<int>(std::lround((x - sim::kTableXMin) / kTexel)); }
int texel_row(double y) { return static_cast<int>(std::lround((sim::kTableHalfY - y) / kTexel)); }
double world_x(int column) { return sim::kTableXMin + column * kTexel; }
double world_y(int row) { return sim::kTableHalfY - row * kTexel; }

struct Board {
  Eigen::Vector2d centre;                  // world x, y
  std::vector<Eigen::Vector3d> corners;    // inner corners in the arm (world) frame, row-major:
                                           // index = ix * kCornersAlongY + iy, x and y ascending
};

// The table texture with a board centred (to the millimetre) at `centre`, and the world positions
// of its inner corners: what the arm would have marked.
Board draw_board(const Eigen::Vector2d& centre, const std::string& png) {
  cv::Mat texture(kTextureHeight, kTextureWidth, CV_8UC3, cv::Scalar(107, 148, 184));  // the table colour, BGR
  const int squares_x = kCornersAlongX + 1, squares_y = kCornersAlongY + 1;
  // Squares span columns [c0, c0 + squares_x * S) (world x ascending) and rows [r0, r0 + squares_y * S)
  // (world y descending).
  const int c0 = texel_column(centre.x()) - squares_x * kSquareTexels / 2;
  const int r0 = texel_row(centre.y()) - squares_y * kSquareTexels / 2;
  const int margin = kSquareTexels;  // a white quiet zone around the squares, as on a printed board
  cv::rectangle(texture, cv::Rect(c0 - margin, r0 - margin, squares_x * kSquareTexels + 2 * margin,
                                  squares_y * kSquareTexels + 2 * margin),
                cv::Scalar(235, 235, 235), cv::FILLED);
  for (int i = 0; i < squares_x; ++i)
    for (int j = 0; j < squares_y; ++j)
      if ((i + j) % 2 == 0)
        cv::rectangle(texture, cv::Rect(c0 + i * kSquareTexels, r0 + j * kSquareTexels, kSquareTexels, kSquareTexels),
                      cv::Scalar(25, 25, 25), cv::FILLED);
  if (!cv::imwrite(png, texture)) throw std::runtime_error("cannot write " + png);
  Board board;
  board.centre = centre;
  for (int ix = 0; ix < kCornersAlongX; ++ix) {
    for (int iy = 0; iy < kCornersAlongY; ++iy) {
      // Inner corner between squares: column c0 + (ix + 1) S; world y ascending = rows descending.
      const int column = c0 + (ix + 1) * kSquareTexels;
      const int row = r0 + (kCornersAlongY - iy) * kSquareTexels;
      board.corners.emplace_back(world_x(column), world_y(row), 0.0);
    }
  }
  return board;
}

// The detected corners reordered to the board's order (x, then y, ascending in the arm's frame).
// OpenCV returns the grid from either end; the cameras face the arm across the table, so world +y
// is to the right in the image and world +x (towards the cameras) is down: the operator's
// knowledge of the set-up, not the simulator's truth.
std::vector<Eigen::Vector2d> in_board_order(const std::vector<cv::Point2f>& found) {
  std::vector<cv::Point2f> c = found;  // rows of kCornersAlongY
  if (c[kCornersAlongY - 1].x < c[0].x) std::reverse(c.begin(), c.end());
  const bool rows_go_down = c[kCornersAlongY].y > c[0].y;
  std::vector<Eigen::Vector2d> out;
  for (int ix = 0; ix < kCornersAlongX; ++ix) {
    const int row = rows_go_down ? ix : kCornersAlongX - 1 - ix;
    for (int iy = 0; iy < kCornersAlongY; ++iy) {
      const cv::Point2f& p = c[row * kCornersAlongY + iy];
      out.emplace_back(p.x, p.y);
    }
  }
  return out;
}

std::vector<Eigen::Vector2d> find_corners(const cv::Mat& bgr, const std::string& what) {
  cv::Mat grey;
  cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
  std::vector<cv::Point2f> corners;
  if (!cv::findChessboardCorners(grey, cv::Size(kCornersAlongY, kCornersAlongX), corners,
                                 cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE))
    throw std::runtime_error(what + ": the board was not found");
  cv::cornerSubPix(grey, corners, cv::Size(5, 5), cv::Size(-1, -1),
                   cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 100, 1e-4));
  return in_board_order(corners);
}

std::string numbers(const Eigen::MatrixXd& m) {
  std::ostringstream s;
  s.precision(12);
  s << "[ ";
  for (int i = 0; i < m.rows(); ++i)
    for (int j = 0; j < m.cols(); ++j) s << (i || j ? ", " : "") << m(i, j);
  s << " ]";
  return s.str();
}

struct Result {
  int boards = 0, corners = 0;
  double translation_error_mm = 0, rotation_error_deg = 0, camera_centre_error_mm = 0;
  double rms_residual_mm = 0, max_residual_mm = 0;
  double plane_angle_error_deg = 0, plane_offset_error_mm = 0, plane_rms_mm = 0;
  std::string image_size;
};

}  // namespace

int main(int argc, char** argv) {
  Flags flags("nudge-exp-calibration-sim",
              "Camera-arm calibration in simulation: checkerboard corners triangulated, absolute orientation by SVD.");
  bool stills = false;
  std::string keep;
  flags.add_bool("stills", &stills, "find the corners in the 1280x960 stills instead of the 640x480 frames");
  flags.add_string("keep", &keep, "keep the board textures and rendered images in this directory");
  double max_translation_mm = 0, max_rotation_deg = 0, noise = 0;
  flags.add_double("noise", &noise, "Gaussian pixel noise (grey levels) in the rendered images");
  flags.add_double("max-translation-mm", &max_translation_mm, "exit 3 if the translation error is larger (0: no check)");
  flags.add_double("max-rotation-deg", &max_rotation_deg, "exit 3 if the rotation error is larger (0: no check)");
  try {
    if (!flags.parse(argc, argv)) return 0;
    if (!(noise >= 0)) throw FlagError("--noise must be >= 0");
    char scratch_template[] = "/tmp/nudge-calibration-XXXXXX";
    const std::string dir = keep.empty() ? std::string(::mkdtemp(scratch_template)) : keep;
    if (dir.empty()) throw std::runtime_error("cannot make a scratch directory");

    // Board poses on the table, in view of both cameras around the workspace.
    const std::vector<Eigen::Vector2d> centres = {{0.25, 0.0}, {0.32, 0.10}, {0.18, -0.10}, {0.35, -0.08}};
    std::vector<Eigen::Vector3d> arm_points, camera_points;
    std::vector<Eigen::Vector2d> all_left, all_right;
    geo::StereoRig rig;
    sim::CameraModel truth_right;
    Result result;
    nudge::Progress progress("nudge-exp-calibration-sim", static_cast<int>(centres.size()) + 1);
    for (size_t k = 0; k < centres.size(); ++k) {
      progress.step("board " + std::to_string(k + 1) + " of " + std::to_string(centres.size()));
      const std::string png = dir + "/board" + std::to_string(k) + ".png";
      const Board board = draw_board(centres[k], png);
      sim::Scene scene;
      scene.source = "calibration board " + std::to_string(k);
      scene.table.kind = sim::Appearance::Kind::Image;
      scene.table.file = png;
      scene.table.repeat = 1;
      scene.table.specular = 0;
      scene.table.reflectance = 0;
      scene.render.noise_sigma = noise;
      sim::World world(scene);
      const sim::CameraModel left_cam = stills ? world.snapshot_camera(0) : world.camera(0);
      const sim::CameraModel right_cam = stills ? world.snapshot_camera(1) : world.camera(1);
      rig = sim::calibrated(left_cam, right_cam);
      truth_right = right_cam;
      const cv::Mat left = stills ? world.render_snapshot(0) : world.render(0);
      const cv::Mat right = stills ? world.render_snapshot(1) : world.render(1);
      result.image_size = std::to_string(left.cols) + "x" + std::to_string(left.rows);
      if (!keep.empty()) {
        cv::imwrite(dir + "/board" + std::to_string(k) + "_left.png", left);
        cv::imwrite(dir + "/board" + std::to_string(k) + "_right.png", right);
      }
      const auto left_corners = find_corners(left, "board " + std::to_string(k) + ", left image");
      const auto right_corners = find_corners(right, "board " + std::to_string(k) + ", right image");
      for (size_t i = 0; i < board.corners.size(); ++i) {
        const auto p = geo::triangulate_point(rig, left_corners[i], right_corners[i]);
        if (!p) throw std::runtime_error("board " + std::to_string(k) + " corner " + std::to_string(i) + ": " + p.reason());
        arm_points.push_back(board.corners[i]);
        camera_points.push_back(*p);
      }
      all_left.insert(all_left.end(), left_corners.begin(), left_corners.end());
      all_right.insert(all_right.end(), right_corners.begin(), right_corners.end());
      ++result.boards;
      if (keep.empty()) std::remove(png.c_str());
    }
    if (keep.empty()) ::rmdir(dir.c_str());
    result.corners = static_cast<int>(arm_points.size());

    // Arm (world) frame -> right camera frame, and the truth it should match.
    progress.step("absolute orientation and table plane");
    const auto fit = geo::absolute_orientation(arm_points, camera_points);
    if (!fit) throw std::runtime_error(fit.reason());
    const geo::RigidTransform& arm_to_right = fit->transform;
    result.translation_error_mm = 1e3 * (arm_to_right.t - truth_right.t).norm();  // the arm base in the camera frame
    result.rotation_error_deg = geo::rotation_angle_between(arm_to_right.R, truth_right.R) / kDeg;
    result.camera_centre_error_mm = 1e3 * (arm_to_right.inverse().t - truth_right.centre()).norm();
    result.rms_residual_mm = 1e3 * fit->rms_residual;
    result.max_residual_mm = 1e3 * fit->max_residual;

    // The table plane from the same corners, against the true plane z = 0 in the camera frame.
    const auto table = geo::table_from_corners(rig, all_left, all_right);
    if (!table) throw std::runtime_error("table plane: " + table.reason());
    const Eigen::Vector3d true_normal = truth_right.R * Eigen::Vector3d::UnitZ();
    const double true_offset = -true_normal.dot(truth_right.t);  // n . p + d = 0 through the arm base
    result.plane_angle_error_deg = std::acos(std::clamp(std::abs(table->normal.dot(true_normal)), 0.0, 1.0)) / kDeg;
    result.plane_offset_error_mm = 1e3 * std::abs(table->normal.dot(true_normal) > 0 ? table->offset - true_offset
                                                                                       : table->offset + true_offset);
    result.plane_rms_mm = 1e3 * table->rms_residual;

    // The calibration file: the rig, the table and the arm base (right camera frame) as the
    // triangulation service reads them, plus the arm -> right camera transform for the arm.
    geo::Workspace workspace;
    workspace.table = *table;
    workspace.arm_base = arm_to_right.t;
    const std::string rig_file = results_dir() + "/calibration_sim.yaml";
    geo::save_rig(rig, workspace, rig_file);
    std::ostringstream extra;
    extra << std::ifstream(rig_file).rdbuf();
    std::string text = extra.str();
    if (!text.empty() && text.back() != '\n') text += '\n';
    text += "# arm (world) frame -> right camera: p_right = arm_to_right_rotation * p_arm + arm_to_right_translation\n";
    text += "arm_to_right_rotation: " + numbers(arm_to_right.R) + "\n";
    text += "arm_to_right_translation: " + numbers(arm_to_right.t.transpose()) + "\n";
    write_file_atomically(rig_file, text);
    progress.note("wrote " + rig_file);
    progress.clear_status();  // the result files' "wrote" lines follow on stderr

    JsonWriter j(6);
    j.begin_object();
    j.field("machine", machine_description()).field("date", today()).field("images", result.image_size);
    j.field("noise_sigma", noise).field("boards", result.boards).field("corners", result.corners);
    j.field("translation_error_mm", result.translation_error_mm).field("rotation_error_deg", result.rotation_error_deg);
    j.field("camera_centre_error_mm", result.camera_centre_error_mm);
    j.field("rms_residual_mm", result.rms_residual_mm).field("max_residual_mm", result.max_residual_mm);
    j.field("table_normal_error_deg", result.plane_angle_error_deg)
        .field("table_offset_error_mm", result.plane_offset_error_mm)
        .field("table_fit_rms_mm", result.plane_rms_mm);
    j.end_object();
    write_result("calibration_sim.json", j.str() + "\n");

    std::ostringstream md;
    md.precision(3);
    md << "# Camera-arm calibration in simulation (thesis App. B)\n\n"
       << "An 8 x 5-corner checkerboard (25 mm squares) printed into the table at " << result.boards
       << " known poses (the points the arm would mark, in its own frame = the world frame of docs/sim.md); "
       << "corners found in both " << result.image_size << " images (OpenCV findChessboardCorners + cornerSubPix), "
       << "triangulated (nudge_geometry triangulate_point), and the arm -> right camera transform found by "
       << "absolute orientation (SVD, Arun et al. 1987). The table plane is fitted to the same corners. "
       << "Pixel noise sigma " << noise << " grey levels. "
       << "Errors against the simulator's true camera pose. `nudge-exp-calibration-sim`"
       << (stills ? " --stills" : "") << (noise > 0 ? " --noise " + std::to_string(noise) : std::string()) << "; the calibration file is `calibration_sim.yaml`.\n\n"
       << "| quantity | value |\n|---|---|\n"
       << "| corners | " << result.corners << " |\n"
       << "| translation error (arm base in the camera frame) | " << result.translation_error_mm << " mm |\n"
       << "| rotation error | " << result.rotation_error_deg << " deg |\n"
       << "| camera centre error (in the arm frame) | " << result.camera_centre_error_mm << " mm |\n"
       << "| corner residual after the fit, rms / max | " << result.rms_residual_mm << " / " << result.max_residual_mm
       << " mm |\n"
       << "| table normal error | " << result.plane_angle_error_deg << " deg |\n"
       << "| table offset error | " << result.plane_offset_error_mm << " mm |\n";
    write_result("calibration_sim.md", md.str());
    std::ostringstream summary;
    summary << result.corners << " corners; translation error " << result.translation_error_mm
            << " mm, rotation error " << result.rotation_error_deg << " deg, table normal "
            << result.plane_angle_error_deg << " deg, offset " << result.plane_offset_error_mm << " mm";
    progress.finish(summary.str());
    if ((max_translation_mm > 0 && !(result.translation_error_mm <= max_translation_mm)) ||
        (max_rotation_deg > 0 && !(result.rotation_error_deg <= max_rotation_deg))) {
      std::cerr << "nudge-exp-calibration-sim: above the limits (" << max_translation_mm << " mm, " << max_rotation_deg
                << " deg)\n";
      return 3;
    }
  } catch (const FlagError& e) {
    std::cerr << "nudge-exp-calibration-sim: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "nudge-exp-calibration-sim: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
