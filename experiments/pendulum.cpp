// Thesis sec. 5.4: bilateral symmetry as a tracking feature, measured on a pendulum.
// A red bottle on a damped pendulum (kinematic: phi(t) = A e^(-alpha t) cos(omega (t - t0)) + B
// about a pivot above the image) with a green colour marker above it and a blue one below, in
// front of four backgrounds (white, red distracters, edge noise, mixed), 25 Hz, 1000 frames each.
//  - Ground truth (Table 5.2): the line through the two markers' colour centroids in every frame,
//    fitted with Ceres to theta(t) = A e^(-alpha t) cos(omega (t - t0)) + B, R(t) = L theta(t) + L0;
//    the mean absolute residuals show how well the marker lines follow a damped pendulum.
//  - Symmetry detection without the Kalman filter (Table 5.3): block motion masks the edges as in
//    the tracker, the fast symmetry detector (Nlines 3) gives its strongest line within angle
//    limits around the previous estimate (thesis sec. 5.4: the tracker's detection with the
//    filter switched off), bounded to +-30 deg of vertical; the previous estimate is the last
//    detection made while the bottle clearly moved (see --steady); the first detection searches
//    +-30 deg of vertical. Error against the marker ground truth; frames within 5 of a turning
//    point ignored. NUDGE_TRACE=1 prints every frame's detection to stderr.
//  - Colour centroid (sec. 5.4.3): hue-saturation histogram (45 x 8) of the bottle, back-projection,
//    motion mask, threshold, largest 8-connected blob, distance of its centroid to the true line.
//   nudge-exp-pendulum [--frames 1000] [--only white|red|edge|mixed] [--half-width 5]
// Writes docs/results/pendulum.{json,md} and pendulum_<background>.png.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <sstream>

#include <ceres/ceres.h>
#include <unistd.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "nudge/flags.hpp"
#include "nudge/json.hpp"
#include "nudge/progress.hpp"
#include "nudge/sim/world.hpp"
#include "nudge/symmetry/detector.hpp"
#include "nudge/symmetry/line.hpp"
#include "nudge/timing.hpp"
#include "nudge/tracking/block_motion.hpp"
#include "nudge/tracking/tracker.hpp"
#include "report.hpp"

using namespace nudge;
using namespace nudge::experiments;
namespace trk = nudge::tracking;
namespace sym = nudge::symmetry;

namespace {

constexpr double kFps = 25.0;
constexpr int kTurningMargin = 5;  // frames ignored on each side of a turning point (thesis)
constexpr double kDetectHalfRangeDeg = 30.0;  // the first detection: theta within +-30 deg of vertical
// Later detections: theta within +- this of the previous frame's detection (0: always the fixed
// range above). Set by --half-width.
double g_half_width_deg = 5.0;
// Only detections made while at least this fraction of the typical (slowly decaying maximum)
// number of moving blocks moves re-centre the limits. Set by --steady.
double g_steady_fraction = 0.6;
// Canny on the colour image (beyond the thesis, which used grey edges): a red bottle in front of
// red distracters of the same brightness keeps its outline. --grey-edges restores the thesis'.
bool g_colour_edges = true;
std::string g_name = "pendulum";  // result file names (--name)

// The rig (metres, world frame). The swing plane is x = kPivot.x(): face-on to the cameras.
const Eigen::Vector3d kPivot(-0.25, 0.0, 1.20);
constexpr double kBottleCentre = 0.65;           // pivot to the bottle's centre
constexpr double kMarkerOffset = 0.1 + 0.015 + 0.0425;  // bottle centre to a marker's centre
// The true motion (the simulated rig's, not the fitted one).
struct Swing {
  double A = 0.22, alpha = 0.025, omega = 2 * M_PI / 4.0, t0 = 0.35, B = 0.012;
  double phi(double t) const { return A * std::exp(-alpha * t) * std::cos(omega * (t - t0)) + B; }
};

// ---- backgrounds
std::string texture_dir() {
  const std::filesystem::path d = std::filesystem::temp_directory_path() / "nudge_exp_textures";
  std::filesystem::create_directories(d);
  return d.string();
}

// Backdrop textures (the backdrop is 2.8 m wide and 1.2 m tall; the texture is stretched over it).
std::string make_background(const std::string& kind) {
  const int n = 1024;
  cv::Mat img(n, n, CV_8UC3, cv::Scalar(242, 244, 245));
  // "mixed" has exactly the lines of "edge" and the blobs of "red".
  const bool red = kind == "red" || kind == "mixed", edge = kind == "edge" || kind == "mixed";
  if (edge) {  // high-contrast straight lines and outlines in every direction
    cv::RNG rng(12);
    for (int i = 0; i < 70; ++i) {
      const cv::Point a(rng.uniform(0, n), rng.uniform(0, n));
      const double ang = rng.uniform(0.0, M_PI);
      const double len = rng.uniform(60.0, 400.0);
      const cv::Point b = a + cv::Point(static_cast<int>(len * std::cos(ang)), static_cast<int>(len * std::sin(ang)));
      cv::line(img, a, b, cv::Scalar(20, 20, 20), rng.uniform(2, 9), cv::LINE_AA);
    }
    for (int i = 0; i < 15; ++i) {
      const cv::Point a(rng.uniform(0, n), rng.uniform(0, n));
      cv::rectangle(img, a, a + cv::Point(rng.uniform(40, 200), rng.uniform(40, 200)), cv::Scalar(30, 30, 30), 4);
    }
  }
  if (red) {  // red and orange blobs, the bottle's hue
    cv::RNG rng(11);
    for (int i = 0; i < 45; ++i) {
      const cv::Point c(rng.uniform(0, n), rng.uniform(0, n));
      const cv::Size axes(rng.uniform(25, 90), rng.uniform(25, 90));
      const cv::Scalar colour(rng.uniform(10, 50), rng.uniform(10, 60), rng.uniform(150, 230));
      if (i % 3 == 0) {
        cv::rectangle(img, c, c + cv::Point(axes.width * 2, axes.height), colour, cv::FILLED);
      } else {
        cv::ellipse(img, c, axes, rng.uniform(0.0, 180.0), 0, 360, colour, cv::FILLED, cv::LINE_AA);
      }
    }
  }
  const std::string file = texture_dir() + "/pendulum_" + kind + ".png";
  const std::string tmp = texture_dir() + "/" + std::to_string(::getpid()) + "_pendulum_" + kind + ".png";
  if (!cv::imwrite(tmp, img)) throw std::runtime_error("cannot write " + tmp);
  std::filesystem::rename(tmp, file);
  return file;
}

sim::Scene pendulum_scene(const std::string& background) {
  // The rig: a red squeeze bottle with a green marker above and a blue one below, 35 cm in front of
  // the backdrop, seen nearly face-on from 75 cm. Built here rather than shipped as a scene file:
  // a scene's objects stand on the table (where this camera does not look) until the pendulum
  // lifts them.
  sim::Scene scene = sim::default_scene();
  scene.source = "pendulum";
  scene.background.colour = Eigen::Vector3d(0.96, 0.96, 0.95);
  scene.rig.target = Eigen::Vector3d(kPivot.x(), 0.0, kPivot.z() - kBottleCentre);
  scene.rig.distance = 0.75;
  scene.rig.elevation = 2.0 * M_PI / 180.0;
  const std::array<std::pair<const char*, Eigen::Vector3d>, 3> parts = {
      {{"bottle", {0.8, 0.08, 0.06}}, {"marker", {0.1, 0.75, 0.15}}, {"marker", {0.1, 0.25, 0.9}}}};
  const char* names[] = {"red_bottle", "green_marker", "blue_marker"};
  for (int i = 0; i < 3; ++i) {
    sim::ObjectSpec o;
    o.kind = parts[i].first;
    o.name = names[i];
    o.position = Eigen::Vector2d(kPivot.x(), 0.12 * i);
    o.appearance.colour = parts[i].second;
    o.appearance.specular = 0.3;
    scene.objects.push_back(o);
  }
  if (background != "white") {
    scene.background.kind = sim::Appearance::Kind::Image;
    scene.background.file = make_background(background);
    scene.background.repeat = 1;
  }
  scene.render.noise_sigma = 1.0;
  sim::validate(scene);
  return scene;
}

void pose_pendulum(sim::World& w, double phi) {
  const Eigen::Quaterniond q(Eigen::AngleAxisd(phi, Eigen::Vector3d::UnitX()));
  const Eigen::Vector3d down = q * Eigen::Vector3d(0, 0, -1);
  const double offsets[] = {kBottleCentre, kBottleCentre - kMarkerOffset, kBottleCentre + kMarkerOffset};
  for (int i = 0; i < 3; ++i) {
    const Eigen::Vector3d centre = kPivot + offsets[i] * down;
    w.set_object_pose(i, centre - q * Eigen::Vector3d(0, 0, 0.5 * w.object(i).height), q);
  }
}

// ---- colour: markers and the colour centroid
bool largest_blob_centroid(const cv::Mat& binary, cv::Point2d* centroid, int min_area = 20) {
  cv::Mat labels, stats, centroids;
  const int n = cv::connectedComponentsWithStats(binary, labels, stats, centroids, 8, CV_32S);
  int best = -1, best_area = min_area - 1;
  for (int i = 1; i < n; ++i) {
    const int area = stats.at<int>(i, cv::CC_STAT_AREA);
    if (area > best_area) {
      best_area = area;
      best = i;
    }
  }
  if (best < 0) return false;
  *centroid = cv::Point2d(centroids.at<double>(best, 0), centroids.at<double>(best, 1));
  return true;
}

bool marker_centroid(const cv::Mat& hsv, int hue_lo, int hue_hi, cv::Point2d* c) {
  cv::Mat m;
  cv::inRange(hsv, cv::Scalar(hue_lo, 110, 40), cv::Scalar(hue_hi, 255, 255), m);
  return largest_blob_centroid(m, c);
}

const int kHistChannels[] = {0, 1};
const int kHistSizes[] = {45, 8};
const float kHueRange[] = {0, 180}, kSatRange[] = {0, 256};
const float* kHistRanges[] = {kHueRange, kSatRange};

cv::Mat value_mask(const cv::Mat& hsv) {  // V rejects very dark and very bright pixels
  cv::Mat m;
  cv::inRange(hsv, cv::Scalar(0, 0, 30), cv::Scalar(180, 256, 240), m);
  return m;
}

// ---- the damped-pendulum fit
struct Fit {
  double p[7] = {0, 0, 0, 0, 0, 0, 0};  // A, alpha, omega, t0, B, L, L0
  double theta(double t) const { return p[0] * std::exp(-p[1] * t) * std::cos(p[2] * (t - p[3])) + p[4]; }
  double r(double t) const { return p[5] * theta(t) + p[6]; }
  double theta_rate(double t) const {
    const double e = std::exp(-p[1] * t), a = p[2] * (t - p[3]);
    return p[0] * e * (-p[1] * std::cos(a) - p[2] * std::sin(a));
  }
  std::string summary;
  bool converged = false;
};

struct PendulumResidual {
  double t, r, theta;
  template <typename T>
  bool operator()(const T* p, T* residual) const {
    using std::cos;
    using std::exp;
    const T th = p[0] * exp(-p[1] * T(t)) * cos(p[2] * (T(t) - p[3])) + p[4];
    residual[0] = (p[5] * th + p[6] - T(r)) / T(1.0);   // px
    residual[1] = (th - T(theta)) / T(0.003);            // rad, weighted like 1 px ~ 0.003 rad
    return true;
  }
};

Fit fit_pendulum(const std::vector<double>& t, const std::vector<double>& r, const std::vector<double>& theta) {
  Fit f;
  const size_t n = t.size();
  if (n < 20) throw std::runtime_error("too few ground-truth frames to fit");
  // Initial guess: B = mean, A = half the range of the first 4 s, omega from mean crossings,
  // t0 = the first maximum, L and L0 by a straight line of R against theta.
  const double b = mean(theta);
  double lo = 1e9, hi = -1e9, t_max = t[0];
  for (size_t i = 0; i < n && t[i] < t[0] + 4.0; ++i) {
    if (theta[i] > hi) {
      hi = theta[i];
      t_max = t[i];
    }
    lo = std::min(lo, theta[i]);
  }
  std::vector<double> crossings;
  for (size_t i = 1; i < n; ++i)
    if ((theta[i - 1] - b) * (theta[i] - b) < 0) crossings.push_back(t[i]);
  const double half_period =
      crossings.size() >= 2 ? (crossings.back() - crossings.front()) / (crossings.size() - 1) : 2.0;
  const LinearFit line = fit_line(theta, r);
  double init[7] = {0.5 * (hi - lo), 0.0, M_PI / half_period, t_max, b, line.slope, line.intercept};
  std::copy(init, init + 7, f.p);
  ceres::Problem problem;
  for (size_t i = 0; i < n; ++i) {
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<PendulumResidual, 2, 7>(
                                 new PendulumResidual{t[i], r[i], theta[i]}),
                             nullptr, f.p);
  }
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  options.max_num_iterations = 200;
  options.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  f.summary = summary.BriefReport();
  f.converged = summary.termination_type == ceres::CONVERGENCE;
  return f;
}

// ---- one video
struct FrameRecord {
  double t = 0;
  bool gt = false;             // both markers found
  double gt_r = 0, gt_theta = 0;
  sim::ImageLine gt_line;      // the marker line
  sim::ImageLine exact;        // the bottle's projected axis
  bool detected = false;       // a symmetry line (frames >= 1)
  double det_votes = 0;
  double det_r = 0, det_theta = 0;
  bool colour = false;
  cv::Point2d centroid;
  bool scored = false;         // not within 5 frames of a turning point (and frame >= 1)
};

struct BackgroundResult {
  std::string name;
  int frames = 0, gt_frames = 0, scored = 0, detected = 0, colour_found = 0;
  Fit fit;
  double gt_res_r = 0, gt_res_theta = 0;
  double r_mean = 0, r_std = 0, r_median = 0, t_mean = 0, t_std = 0, t_median = 0;
  double r_exact_mean = 0, t_exact_mean = 0, gt_vs_exact_r = 0, gt_vs_exact_theta = 0;
  double colour_mean = 0, colour_median = 0;
  double ms_render = 0, ms_detect = 0;
  cv::Mat plot_image, example;
};

double stddev(const std::vector<double>& v) {
  if (v.size() < 2) return 0;
  const double m = mean(v);
  double s = 0;
  for (double x : v) s += (x - m) * (x - m);
  return std::sqrt(s / (v.size() - 1));
}

std::vector<double> absolute(std::vector<double> v) {
  for (double& x : v) x = std::abs(x);
  return v;
}

BackgroundResult run_background(const std::string& name, int frames, nudge::Progress& progress) {
  BackgroundResult res;
  res.name = name;
  res.frames = frames;
  sim::World world(pendulum_scene(name));
  world.pusher_visible = false;
  world.park_pusher();
  const Swing swing;
  trk::TrackerParams tp;  // the tracker's motion, edge and detector settings
  bool have_previous = false;  // a previous detection centres the angle limits
  double previous_theta_deg = 0;
  double moving_typical = 0;  // slowly decaying maximum of the moving-block count
  cv::Mat hist, prev_grey;
  std::vector<FrameRecord> rec(frames);
  const int w = world.camera(0).lens.width, h = world.camera(0).lens.height;
  Stopwatch render_watch;
  double render_ms = 0, detect_ms = 0;
  for (int k = 0; k < frames; ++k) {
    FrameRecord& f = rec[k];
    f.t = k / kFps;
    pose_pendulum(world, swing.phi(f.t));
    render_watch.restart();
    const cv::Mat img = world.render(0);
    render_ms += render_watch.elapsed_ms();
    f.exact = world.axis_in_image(0, 0);
    cv::Mat hsv, grey;
    cv::cvtColor(img, hsv, cv::COLOR_BGR2HSV);
    cv::cvtColor(img, grey, cv::COLOR_BGR2GRAY);
    if (k == 0) {  // the bottle's colour model, from its true mask ("built offline")
      const cv::Mat mask = world.render_mask(0) == 1;
      cv::calcHist(&hsv, 1, kHistChannels, mask & value_mask(hsv), hist, 2, kHistSizes, kHistRanges);
      cv::normalize(hist, hist, 0, 255, cv::NORM_MINMAX);
    }
    cv::Point2d green, blue;
    if (marker_centroid(hsv, 45, 80, &green) && marker_centroid(hsv, 105, 130, &blue)) {
      f.gt_line = sim::line_through({green.x, green.y}, {blue.x, blue.y}, w, h);
      f.gt = f.gt_line.valid;
      f.gt_r = f.gt_line.r;
      f.gt_theta = f.gt_line.theta;
    }
    if (k > 0) {
      Stopwatch dw;
      const trk::BlockMotion motion = trk::detect_block_motion(prev_grey, grey, tp.motion);
      const cv::Mat imask = trk::upscale_blocks(motion.blocks, motion.block_size, w, h);
      cv::Mat edge_image;
      sym::EdgeParams edge_params = tp.edges;
      edge_params.colour = g_colour_edges;
      sym::detect_edges(g_colour_edges ? img : grey, edge_params, &edge_image);
      const sym::EdgeSet edges = sym::edges_from_mask(trk::mask_edges(edge_image, imask));
      if (!edges.points.empty()) {
        sym::Params dp = tp.detector;
        dp.theta_min_deg = -kDetectHalfRangeDeg;
        dp.theta_max_deg = kDetectHalfRangeDeg;
        if (have_previous && g_half_width_deg > 0) {
          // Around the previous detection, within the rig's range (the swing never leaves it): a
          // wrong line at a turning point cannot drag later searches to a horizontal "symmetry".
          const double lo = std::max(-kDetectHalfRangeDeg, previous_theta_deg - g_half_width_deg);
          const double hi = std::min(kDetectHalfRangeDeg, previous_theta_deg + g_half_width_deg);
          if (lo < hi) {
            dp.theta_min_deg = lo;
            dp.theta_max_deg = hi;
          }
        }
        sym::Detector detector(dp, tp.edges);
        const sym::Result r = detector.detect(edges);
        if (!r.lines.empty()) {
          f.detected = true;
          f.det_r = r.lines[0].r;
          f.det_theta = r.lines[0].theta;
          f.det_votes = r.lines[0].votes;
          // The limits follow detections made with the bottle clearly moving: near a turning
          // point the bottle hardly moves, few of its edges survive the motion mask, and a
          // background line may win; centring the next search on it would keep it.
          if (motion.moving_blocks >= g_steady_fraction * moving_typical) {
            have_previous = true;
            previous_theta_deg = f.det_theta * 180.0 / M_PI;
          }
        }
      }
      detect_ms += dw.elapsed_ms();
      moving_typical = std::max(0.98 * moving_typical, static_cast<double>(motion.moving_blocks));
      if (std::getenv("NUDGE_TRACE"))  // per-frame trace for debugging (stderr)
        std::cerr << name << " #" << k << " edges " << edges.points.size() << " exact " << f.exact.r << "/"
                  << f.exact.theta * 180 / M_PI << (f.detected ? " det " : " none ") << f.det_r << "/"
                  << f.det_theta * 180 / M_PI << " moving " << motion.moving_blocks << " votes " << f.det_votes << "\n";
      cv::Mat back;
      cv::calcBackProject(&hsv, 1, kHistChannels, hist, back, kHistRanges);
      back &= value_mask(hsv);
      back &= imask;
      cv::Mat blob = back > 64;
      f.colour = largest_blob_centroid(blob, &f.centroid);
      if (k == frames / 2) {
        res.example = img.clone();
        cv::Mat bgr;
        cv::cvtColor(blob, bgr, cv::COLOR_GRAY2BGR);
        cv::hconcat(res.example, bgr, res.example);
      }
    }
    prev_grey = grey;
  }
  res.ms_render = render_ms / frames;
  res.ms_detect = detect_ms / std::max(1, frames - 1);

  // Table 5.2: fit the marker lines.
  std::vector<double> ts, rs, ths;
  for (const auto& f : rec)
    if (f.gt) {
      ts.push_back(f.t);
      rs.push_back(f.gt_r);
      ths.push_back(f.gt_theta);
    }
  res.gt_frames = static_cast<int>(ts.size());
  res.fit = fit_pendulum(ts, rs, ths);
  std::vector<double> res_r, res_t;
  for (size_t i = 0; i < ts.size(); ++i) {
    res_r.push_back(std::abs(rs[i] - res.fit.r(ts[i])));
    res_t.push_back(std::abs(ths[i] - res.fit.theta(ts[i])));
  }
  res.gt_res_r = mean(res_r);
  res.gt_res_theta = mean(res_t);

  // Turning points of the fitted motion; frames within 5 of one are not scored.
  std::vector<int> turning;
  for (int k = 1; k < frames; ++k)
    if (res.fit.theta_rate(rec[k - 1].t) * res.fit.theta_rate(rec[k].t) <= 0) turning.push_back(k);
  for (int k = 1; k < frames; ++k) {
    bool near = false;
    for (int tk : turning) near = near || std::abs(k - tk) <= kTurningMargin;
    rec[k].scored = !near && rec[k].gt;
  }

  // Table 5.3 and the colour centroid.
  std::vector<double> er, et, er_exact, et_exact, gx_r, gx_t, ec;
  std::vector<double> plot_k, plot_er, plot_ec, plot_gt, plot_k_t, plot_et, plot_gt_t;
  const double mean_gt_r = mean(rs), mean_gt_t = mean(ths);
  for (int k = 1; k < frames; ++k) {
    const FrameRecord& f = rec[k];
    if (!f.scored) continue;
    ++res.scored;
    const auto gx = sym::line_difference(f.gt_r, f.gt_theta, f.exact.r, f.exact.theta);
    gx_r.push_back(std::abs(gx.r));
    gx_t.push_back(std::abs(gx.theta));
    if (f.detected) {
      ++res.detected;
      const auto d = sym::line_difference(f.det_r, f.det_theta, f.gt_r, f.gt_theta);
      er.push_back(d.r);
      et.push_back(d.theta);
      const auto dx = sym::line_difference(f.det_r, f.det_theta, f.exact.r, f.exact.theta);
      er_exact.push_back(std::abs(dx.r));
      et_exact.push_back(std::abs(dx.theta));
      if (k < 400) {
        plot_k.push_back(k);
        plot_er.push_back(d.r);
        plot_k_t.push_back(k);
        plot_et.push_back(d.theta * 180 / M_PI);
      }
    }
    if (f.colour) {
      ++res.colour_found;
      const double e = std::abs(sim::signed_distance(f.gt_line, {f.centroid.x, f.centroid.y}, w, h));
      ec.push_back(e);
      if (k < 400) plot_ec.push_back(e);
    }
  }
  res.r_mean = er.empty() ? NAN : mean(absolute(er));
  res.r_std = stddev(er);
  res.r_median = er.empty() ? NAN : median(absolute(er));
  res.t_mean = et.empty() ? NAN : mean(absolute(et));
  res.t_std = stddev(et);
  res.t_median = et.empty() ? NAN : median(absolute(et));
  res.r_exact_mean = er_exact.empty() ? NAN : mean(er_exact);
  res.t_exact_mean = et_exact.empty() ? NAN : mean(et_exact);
  res.gt_vs_exact_r = gx_r.empty() ? NAN : mean(gx_r);
  res.gt_vs_exact_theta = gx_t.empty() ? NAN : mean(gx_t);
  res.colour_mean = ec.empty() ? NAN : mean(ec);
  res.colour_median = ec.empty() ? NAN : median(ec);

  // Plots of the first 400 frames (thesis figs. 5.14-5.17 and 5.24-5.27).
  std::vector<double> all_k, gt_r_centred, gt_t_centred, ck;
  for (int k = 1; k < std::min(frames, 400); ++k) {
    if (!rec[k].gt) continue;
    all_k.push_back(k);
    gt_r_centred.push_back((rec[k].gt_r - mean_gt_r) / 20.0);
    gt_t_centred.push_back((rec[k].gt_theta - mean_gt_t) * 180 / M_PI / 5.0);
  }
  for (int k = 1; k < std::min(frames, 400); ++k)
    if (rec[k].scored && rec[k].colour) ck.push_back(k);
  const cv::Mat pr = plot({Series{"symmetry R error (px)", plot_k, plot_er, cv::Scalar(200, 80, 0), true},
                           Series{"colour centroid distance (px)", ck, plot_ec, cv::Scalar(0, 140, 230), true},
                           Series{"truth R - mean (px / 20)", all_k, gt_r_centred, cv::Scalar(60, 60, 60), false}},
                          name + ": R and colour centroid", "frame", "px", {720, 360});
  const cv::Mat pt = plot({Series{"symmetry theta error (deg)", plot_k_t, plot_et, cv::Scalar(200, 80, 0), true},
                           Series{"truth theta - mean (deg / 5)", all_k, gt_t_centred, cv::Scalar(60, 60, 60), false}},
                          name + ": theta", "frame", "deg", {720, 360});
  cv::hconcat(pr, pt, res.plot_image);

  std::ostringstream line;
  line << name << ": GT fit residuals " << res.gt_res_r << " px / " << res.gt_res_theta << " rad (" << res.fit.summary
       << "), detection |R| " << res.r_mean << " px |theta| " << res.t_mean << " rad over " << res.detected << "/"
       << res.scored << " scored frames, colour centroid " << res.colour_mean << " px (" << res.colour_found
       << "), render " << res.ms_render << " ms/frame, detect " << res.ms_detect << " ms/frame";
  progress.note(line.str());
  return res;
}

void write_results(const std::vector<BackgroundResult>& rs, int frames) {
  const Swing s;
  JsonWriter j;
  j.begin_object();
  j.field("machine", machine_description()).field("date", today()).field("frames", frames);
  j.field("turning_margin_frames", kTurningMargin).field("detect_half_range_deg", kDetectHalfRangeDeg);
  j.field("detect_half_width_around_previous_deg", g_half_width_deg).field("steady_fraction", g_steady_fraction);
  j.field("edges", g_colour_edges ? "colour" : "grey");
  j.key("true_swing").begin_object();
  j.field("A_rad", s.A).field("alpha_per_s", s.alpha).field("omega_rad_per_s", s.omega).field("t0_s", s.t0);
  j.field("B_rad", s.B).end_object();
  for (const auto& r : rs) {
    j.key(r.name).begin_object();
    j.field("gt_residual_r_px", r.gt_res_r).field("gt_residual_theta_rad", r.gt_res_theta);
    j.field("gt_frames", r.gt_frames).field("fit_converged", r.fit.converged);
    j.key("fit").begin_object();
    j.field("A", r.fit.p[0]).field("alpha", r.fit.p[1]).field("omega", r.fit.p[2]).field("t0", r.fit.p[3]);
    j.field("B", r.fit.p[4]).field("L", r.fit.p[5]).field("L0", r.fit.p[6]).end_object();
    j.field("scored_frames", r.scored).field("detected_frames", r.detected);
    j.field("r_abs_mean_px", r.r_mean).field("r_std_px", r.r_std).field("r_abs_median_px", r.r_median);
    j.field("theta_abs_mean_rad", r.t_mean).field("theta_std_rad", r.t_std).field("theta_abs_median_rad", r.t_median);
    j.field("r_abs_mean_vs_exact_px", r.r_exact_mean).field("theta_abs_mean_vs_exact_rad", r.t_exact_mean);
    j.field("gt_vs_exact_r_px", r.gt_vs_exact_r).field("gt_vs_exact_theta_rad", r.gt_vs_exact_theta);
    j.field("colour_centroid_abs_mean_px", r.colour_mean).field("colour_centroid_abs_median_px", r.colour_median);
    j.field("colour_frames", r.colour_found);
    j.field("ms_render", r.ms_render).field("ms_detect", r.ms_detect);
    j.end_object();
  }
  j.end_object();
  write_result(g_name + ".json", j.str() + "\n");

  const double thesis52[4][2] = {{0.39, 0.0014}, {0.76, 0.0021}, {1.82, 0.0025}, {0.51, 0.0014}};
  const double thesis53[4][2] = {{1.13, 0.0057}, {2.06, 0.0134}, {1.21, 0.0078}, {3.41, 0.0192}};
  auto thesis_row = [](const std::string& n) {
    return n == "white" ? 0 : n == "red" ? 1 : n == "edge" ? 2 : 3;
  };
  std::ostringstream md;
  md.precision(3);
  md << "# Pendulum — thesis sec. 5.4, Tables 5.2 and 5.3, colour centroid (sec. 5.4.3)\n\n"
     << "Simulated rig (built in `experiments/pendulum.cpp`, left camera, 640×480, 25 Hz, " << frames
     << " frames per background, σ 1 pixel noise): a red bottle on a pendulum arm between a green marker "
        "(above) and a blue one (below), swung kinematically about a pivot 65 cm above the bottle's centre: "
        "φ(t) = " << s.A << "·e^(−" << s.alpha << "·t)·cos(" << s.omega << "·(t − " << s.t0 << ")) + " << s.B
     << " rad. Backgrounds: plain white; red (red/orange blobs on white); edge (black lines and outlines on "
        "white); mixed (the same lines and blobs together).\n\n"
     << "**Ground truth** = the line through the two markers' colour centroids (HSV filter, largest blob), "
        "fitted with Ceres to θ(t) = A·e^(−αt)·cos(ω(t − t0)) + B, R(t) = L·θ(t) + L0 (A, α, ω, t0, B, L, L0 "
        "free). **Detection** without the Kalman filter: block motion masks the Canny edges as in the tracker "
     << (g_colour_edges ? "(Canny on the colour image: the thesis used grey edges, `--grey-edges`); " : "(grey edges, as the thesis); ")
     << "the fast symmetry detector (Dmin 25, Dmax 250, Nlines 3) gives its strongest line, with θ limited "
        "to ±" << g_half_width_deg << "° around the previous estimate (thesis sec. 5.4: the tracker's "
        "detection with the filter switched off) and to ±" << kDetectHalfRangeDeg << "° of vertical; the "
        "previous estimate is the last detection made while the bottle clearly moved (at least "
        << g_steady_fraction << " × the typical number of moving blocks; near turning points a background "
        "line may win and must not steer the next search). The first detection searches ±" << kDetectHalfRangeDeg
     << "° of vertical. Frames within " << kTurningMargin
     << " of a turning point of the fitted motion are ignored. **Colour centroid**: hue–saturation histogram "
        "(45 × 8) of the bottle's true mask in frame 0, V < 30 or V > 240 rejected, back-projection, motion mask, "
        "threshold 64/255, largest 8-connected blob, distance of its centroid to the ground-truth line.\n\n"
     << "Machine: " << machine_description() << ", " << today() << ".\n\n"
     << "## Table 5.2 — ground truth, mean absolute regression residuals\n\n"
     << "| background | R px | θ rad | thesis R px | thesis θ rad | frames with both markers |\n|---|---|---|---|---|---|\n";
  for (const auto& r : rs) {
    const int t = thesis_row(r.name);
    md << "| " << r.name << " | " << r.gt_res_r << " | " << r.gt_res_theta << " | " << thesis52[t][0] << " | "
       << thesis52[t][1] << " | " << r.gt_frames << " |\n";
  }
  md << "\n## Table 5.3 — symmetry detection error (no Kalman filter)\n\n"
     << "| background | \\|R\\| mean px | R std px | \\|R\\| median px | \\|θ\\| mean rad | θ std rad | "
        "\\|θ\\| median rad | thesis \\|R\\| / \\|θ\\| | detected / scored frames |\n|---|---|---|---|---|---|---|---|---|\n";
  for (const auto& r : rs) {
    const int t = thesis_row(r.name);
    md << "| " << r.name << " | " << r.r_mean << " | " << r.r_std << " | " << r.r_median << " | " << r.t_mean << " | "
       << r.t_std << " | " << r.t_median << " | " << thesis53[t][0] << " / " << thesis53[t][1] << " | " << r.detected
       << " / " << r.scored << " |\n";
  }
  md << "\nAgainst the exact projected bottle axis instead of the marker line, and the marker line against it:\n\n"
     << "| background | detection \\|R\\| px | detection \\|θ\\| rad | marker line \\|R\\| px | marker line \\|θ\\| rad |\n"
     << "|---|---|---|---|---|\n";
  for (const auto& r : rs)
    md << "| " << r.name << " | " << r.r_exact_mean << " | " << r.t_exact_mean << " | " << r.gt_vs_exact_r << " | "
       << r.gt_vs_exact_theta << " |\n";
  md << "\n## Colour centroid (sec. 5.4.3)\n\n| background | mean distance px | median px | frames with a blob / scored |\n"
     << "|---|---|---|---|\n";
  for (const auto& r : rs)
    md << "| " << r.name << " | " << r.colour_mean << " | " << r.colour_median << " | " << r.colour_found << " / "
       << r.scored << " |\n";
  md << "\nPlots (first 400 frames): ";
  for (const auto& r : rs) md << "[" << r.name << "](pendulum_" << r.name << ".png) ";
  md << "\n";
  for (const auto& r : rs) md << "\n![" << r.name << "](pendulum_" << r.name << ".png)\n";
  write_result(g_name + ".md", md.str());
  for (const auto& r : rs) {
    cv::Mat out = r.plot_image;
    if (!r.example.empty()) {
      cv::Mat ex;
      cv::resize(r.example, ex, {out.cols, out.cols * r.example.rows / r.example.cols}, 0, 0, cv::INTER_AREA);
      cv::vconcat(out, ex, out);
    }
    write_png(g_name + "_" + r.name + ".png", out);
  }
}

}  // namespace

int main(int argc, char** argv) {
  int frames = 1000;
  std::string only;
  Flags flags("nudge-exp-pendulum", "Thesis sec. 5.4: pendulum ground truth, detection error and colour centroid.");
  flags.add_int("frames", &frames, "frames per background (thesis: 1000)");
  flags.add_double("half-width", &g_half_width_deg,
                   "angle limits: previous detection +- this many degrees (0: always +-30 deg of vertical)");
  flags.add_double("steady", &g_steady_fraction,
                   "only detections with at least this fraction of the typical motion re-centre the limits");
  bool grey_edges = false;
  flags.add_bool("grey-edges", &grey_edges, "Canny on the grey image, as the thesis (default: colour edges)");
  flags.add_string("name", &g_name,
                   "result files docs/results/NAME.{json,md} and NAME_<background>.png (pendulum_thesis_settings: "
                   "run with --grey-edges --steady 0, the thesis' choices)");
  flags.add_string("only", &only, "run only this background (white, red, edge, mixed; results are not written)");
  try {
    if (!flags.parse(argc, argv)) return 0;
    g_colour_edges = !grey_edges;
    if (frames < 60) throw FlagError("--frames: at least 60 (the fit needs a few swings)");
    if (!(g_half_width_deg >= 0 && g_half_width_deg < 90)) throw FlagError("--half-width: in [0, 90)");
    if (!(g_steady_fraction >= 0 && g_steady_fraction <= 1)) throw FlagError("--steady: in [0, 1]");
    std::vector<BackgroundResult> results;
    const std::vector<std::string> backgrounds = {"white", "red", "edge", "mixed"};
    if (!only.empty() && std::find(backgrounds.begin(), backgrounds.end(), only) == backgrounds.end())
      throw FlagError("--only: one of white, red, edge, mixed");
    nudge::Progress progress("nudge-exp-pendulum", only.empty() ? static_cast<int>(backgrounds.size()) : 1);
    for (const std::string& name : backgrounds) {
      if (!only.empty() && name != only) continue;
      progress.step(name + " background, " + std::to_string(frames) + " frames");
      results.push_back(run_background(name, frames, progress));
    }
    progress.clear_status();  // the result files' "wrote" lines follow on stderr
    if (only.empty()) write_results(results, frames);
    progress.finish(std::to_string(results.size()) + " background(s) of " + std::to_string(frames) + " frames" +
                    (only.empty() ? "" : " (--only: nothing written)"));
  } catch (const std::exception& e) {
    std::cerr << "nudge-exp-pendulum: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
