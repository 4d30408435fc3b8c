#include "tracking_scenarios.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <unistd.h>

#include <filesystem>
#include <utility>

#include "nudge/timing.hpp"

namespace nudge::experiments {

namespace {

using Eigen::Quaterniond;
using Eigen::Vector3d;

constexpr double kDeg = M_PI / 180.0;

sim::ObjectSpec object(const std::string& kind, const std::string& name, double x, double y,
                       const Vector3d& colour) {
  sim::ObjectSpec o;
  o.kind = kind;
  o.name = name;
  o.position = Eigen::Vector2d(x, y);
  o.appearance.colour = colour;
  return o;
}

sim::ObjectSpec checkered(sim::ObjectSpec o, const Vector3d& colour2, double repeat) {
  o.appearance.kind = sim::Appearance::Kind::Checker;
  o.appearance.colour2 = colour2;
  o.appearance.repeat = repeat;
  return o;
}

// Textures made here (deterministic) and written once per process to a temporary directory:
// a printed label (text, logo blocks) and multi-coloured patches. Unlike a checker, neither is
// mirror-symmetric about horizontal lines.
std::string texture_file(const std::string& name) {
  static std::string dir;
  if (dir.empty()) {
    const std::filesystem::path d =
        std::filesystem::temp_directory_path() / "nudge_exp_textures";
    std::filesystem::create_directories(d);
    cv::RNG rng(20080601);
    cv::Mat label(512, 512, CV_8UC3, cv::Scalar(170, 70, 30));  // BGR: blue bottle
    cv::rectangle(label, {0, 170}, {511, 350}, cv::Scalar(235, 245, 250), cv::FILLED);
    for (int i = 0; i < 14; ++i) {
      const cv::Point p(rng.uniform(0, 480), rng.uniform(180, 330));
      cv::rectangle(label, p, p + cv::Point(rng.uniform(8, 40), rng.uniform(6, 20)),
                    cv::Scalar(rng.uniform(0, 255), rng.uniform(0, 255), rng.uniform(0, 255)), cv::FILLED);
    }
    cv::putText(label, "NUDGE", {40, 260}, cv::FONT_HERSHEY_DUPLEX, 2.6, cv::Scalar(30, 30, 200), 6);
    cv::putText(label, "fresh 500 ml", {150, 320}, cv::FONT_HERSHEY_SIMPLEX, 1.2, cv::Scalar(40, 40, 40), 2);
    cv::circle(label, {420, 90}, 40, cv::Scalar(40, 200, 240), cv::FILLED);
    cv::Mat patches(256, 256, CV_8UC3, cv::Scalar(30, 200, 230));  // yellow
    const cv::Scalar colours[] = {{30, 30, 200}, {40, 160, 40}, {200, 90, 30}, {240, 240, 240}, {30, 120, 240}};
    for (int i = 0; i < 40; ++i) {
      const cv::Point p(rng.uniform(-20, 250), rng.uniform(-20, 250));
      cv::rectangle(patches, p, p + cv::Point(rng.uniform(15, 70), rng.uniform(15, 70)), colours[i % 5], cv::FILLED);
    }
    for (const auto& [file, image] : {std::pair<std::string, cv::Mat>{"label.png", label}, {"patches.png", patches}}) {
      const std::filesystem::path tmp = d / (std::to_string(::getpid()) + "_" + file);
      if (!cv::imwrite(tmp.string(), image)) throw std::runtime_error("cannot write " + tmp.string());
      std::filesystem::rename(tmp, d / file);
    }
    dir = d.string();
  }
  return dir + "/" + name;
}

sim::ObjectSpec textured(sim::ObjectSpec o, const std::string& texture, double repeat) {
  o.appearance.kind = sim::Appearance::Kind::Image;
  o.appearance.file = texture_file(texture);
  o.appearance.repeat = repeat;
  return o;
}

sim::Scene base_scene(double noise_sigma = 1.0) {
  sim::Scene s = sim::default_scene();
  s.source = "tracking_scenarios";
  s.render.noise_sigma = noise_sigma;  // a camera is never noise-free
  return s;
}

// Progress through the motion: 0 during the still frames, then linear to 1 at the last frame.
double progress(const Scenario& sc, int k) {
  const int moving = std::max(1, sc.frames - 1 - sc.still_frames);
  return std::clamp(static_cast<double>(k - sc.still_frames) / moving, 0.0, 1.0);
}

double ease(double s) { return 0.5 - 0.5 * std::cos(M_PI * std::clamp(s, 0.0, 1.0)); }

Quaterniond about(const Vector3d& axis, double angle) {
  return Quaterniond(Eigen::AngleAxisd(angle, axis.normalized()));
}

// Direction from a point towards camera 0 (rotating about it turns the object in that image).
Vector3d view_axis(const sim::World& w, const Vector3d& p) { return (w.camera(0).centre() - p).normalized(); }

// Horizontal axis perpendicular to the view: rotating about it tilts an object towards or away
// from camera 0.
Vector3d tilt_axis(const sim::World& w, const Vector3d& p) {
  Vector3d a = view_axis(w, p).cross(Vector3d::UnitZ());
  return a.normalized();
}

// Places object i so that the middle of its axis is at `centre`, turned by q.
void pose_centre(sim::World& w, int i, const Vector3d& centre, const Quaterniond& q) {
  const double h = w.object(i).height;
  w.set_object_pose(i, centre - q * Vector3d(0, 0, 0.5 * h), q);
}

// Upright on the table at (x, y), turned by q about its base centre.
void pose_base(sim::World& w, int i, double x, double y, const Quaterniond& q = Quaterniond::Identity()) {
  w.set_object_pose(i, Vector3d(x, y, 0), q);
}

Scenario light_bottle_turning() {
  Scenario sc;
  sc.name = "light_bottle_turning";
  sc.thesis_video = "1";
  sc.description = "pale, glossy bottle on a pale table and wall (a transparent bottle's weak edges), "
                   "held up and turned from -30 to +90 deg while moving across";
  sc.scene = base_scene();
  sc.scene.table.colour = Vector3d(0.82, 0.8, 0.76);
  sc.scene.background.colour = Vector3d(0.93, 0.93, 0.92);
  sim::ObjectSpec b = object("bottle", "light_bottle", 0.22, -0.13, Vector3d(0.86, 0.9, 0.88));
  b.appearance.specular = 0.9;
  b.appearance.shininess = 0.9;
  sc.scene.objects = {b, object("cup", "white_cup", 0.34, 0.16, Vector3d(0.95, 0.95, 0.95))};
  sc.frames = 126;
  sc.pose = [sc](sim::World& w, int k) {
    const double s = progress(sc, k);
    const Vector3d c(0.22, -0.13 + 0.26 * s, 0.14);
    pose_centre(w, 0, c, about(view_axis(w, c), (-30.0 + 120.0 * ease(s)) * kDeg));
  };
  return sc;
}

Scenario cup_tilt() {
  Scenario sc;
  sc.name = "cup_tilt";
  sc.thesis_video = "3";
  sc.description = "white cup held up and rolled through 130 deg (-65 to +65) in the image while "
                   "tilting up to 35 deg towards the camera";
  sc.scene = base_scene();
  sc.scene.objects = {object("cup", "white_cup", 0.25, 0.0, Vector3d(0.95, 0.95, 0.95)),
                      object("mug", "static_mug", 0.36, -0.17, Vector3d(0.2, 0.35, 0.75))};
  sc.frames = 116;
  sc.pose = [sc](sim::World& w, int k) {
    const double s = progress(sc, k);
    const Vector3d c(0.25, -0.04 + 0.08 * s, 0.10);
    const Quaterniond roll = about(view_axis(w, c), (-65.0 + 130.0 * s) * kDeg);
    const Quaterniond tilt = about(tilt_axis(w, c), 35.0 * std::sin(M_PI * s) * kDeg);
    pose_centre(w, 0, c, tilt * roll);
  };
  return sc;
}

Scenario textured_bottle_scale() {
  Scenario sc;
  sc.name = "textured_bottle_scale";
  sc.thesis_video = "5, 6";
  sc.description = "bottle with a printed label slid diagonally from the back of the table towards the camera and "
                   "back (large scale change), tilting 40 deg away at the end";
  sc.scene = base_scene();
  sc.scene.objects = {textured(object("bottle", "textured_bottle", -0.12, -0.16, Vector3d(1, 1, 1)), "label.png", 1),
                      object("cup", "white_cup", 0.1, 0.22, Vector3d(0.95, 0.95, 0.95))};
  sc.frames = 146;
  sc.pose = [sc](sim::World& w, int k) {
    const double s = progress(sc, k);
    // Diagonally towards the camera and back along another diagonal.
    const double x = s < 0.5 ? -0.12 + 0.47 * ease(2 * s) : 0.35 - 0.37 * ease(2 * s - 1);
    const double y = s < 0.5 ? -0.16 + 0.28 * ease(2 * s) : 0.12 - 0.1 * ease(2 * s - 1);
    const Vector3d base(x, y, 0);
    const double tilt = 40.0 * std::clamp((s - 0.75) / 0.25, 0.0, 1.0);
    w.set_object_pose(0, base, about(tilt_axis(w, base), -tilt * kDeg));
  };
  return sc;
}

Scenario multicolour_mug() {
  Scenario sc;
  sc.name = "multicolour_mug";
  sc.thesis_video = "7";
  sc.description = "mug with multi-coloured patches slid along an arc while turning its handle, with a "
                   "5-frame jump half way (the thesis' capture lag); a white bottle stands by";
  sc.scene = base_scene();
  sim::ObjectSpec mug = textured(object("mug", "multicolour_mug", 0.15, -0.1, Vector3d(1, 1, 1)), "patches.png", 2);
  sc.scene.objects = {mug, object("bottle", "white_bottle", 0.1, 0.2, Vector3d(0.92, 0.92, 0.95))};
  sc.frames = 126;
  sc.pose = [sc](sim::World& w, int k) {
    // The clock jumps by 5 frames at the middle of the motion.
    const int mid = sc.still_frames + (sc.frames - sc.still_frames) / 2;
    const int kk = k >= mid ? k + 5 : k;
    Scenario longer = sc;
    longer.frames = sc.frames + 5;
    const double s = progress(longer, kk);
    const double phi = (-120.0 + 180.0 * s) * kDeg;
    pose_base(w, 0, 0.25 + 0.1 * std::cos(phi), 0.12 * std::sin(phi),
              about(Vector3d::UnitZ(), (30.0 + 200.0 * s) * kDeg));
  };
  return sc;
}

Scenario same_colour_occlusion() {
  Scenario sc;
  sc.name = "same_colour_occlusion";
  sc.thesis_video = "2";
  sc.description = "green bottle slid across behind a static green can that hides its lower part";
  sc.scene = base_scene();
  sc.scene.objects = {object("bottle", "green_bottle", 0.17, -0.2, Vector3d(0.15, 0.55, 0.2)),
                      object("can", "green_can", 0.27, 0.0, Vector3d(0.12, 0.5, 0.18))};
  sc.frames = 126;
  sc.pose = [sc](sim::World& w, int k) { pose_base(w, 0, 0.17, -0.2 + 0.4 * progress(sc, k)); };
  return sc;
}

Scenario mug_behind_cup() {
  Scenario sc;
  sc.name = "mug_behind_cup";
  sc.thesis_video = "4";
  sc.description = "blue mug slid behind a static white cup, reversing direction while occluded";
  sc.scene = base_scene();
  sc.scene.objects = {object("mug", "blue_mug", 0.22, -0.2, Vector3d(0.2, 0.35, 0.75)),
                      object("cup", "white_cup", 0.31, 0.0, Vector3d(0.95, 0.95, 0.95))};
  sc.frames = 116;
  sc.pose = [sc](sim::World& w, int k) {
    const double s = progress(sc, k);
    const double y = s < 0.6 ? -0.2 + 0.19 * (s / 0.6) : -0.01 - 0.15 * ((s - 0.6) / 0.4);
    pose_base(w, 0, 0.22, y, about(Vector3d::UnitZ(), 200 * kDeg));
  };
  return sc;
}

Scenario crossing() {
  Scenario sc;
  sc.name = "crossing";
  sc.thesis_video = "9";
  sc.description = "a blue cup (the target) and, starting 12 frames later, a yellow bottle behind it "
                   "slid in opposite directions; their symmetry lines cross";
  sc.scene = base_scene();
  sc.scene.objects = {object("bottle", "yellow_bottle", 0.16, -0.18, Vector3d(0.9, 0.85, 0.45)),
                      object("cup", "blue_cup", 0.33, 0.18, Vector3d(0.2, 0.35, 0.8))};
  sc.target = 1;
  sc.frames = 116;
  sc.pose = [sc](sim::World& w, int k) {
    // The cup starts first (the tracker starts on it), the bottle 12 frames later; both end together.
    const double s = progress(sc, k);
    Scenario later = sc;
    later.still_frames = sc.still_frames + 12;
    pose_base(w, 0, 0.16, -0.18 + 0.36 * progress(later, k));
    pose_base(w, 1, 0.33, 0.18 - 0.36 * s);
  };
  return sc;
}

Scenario collision() {
  Scenario sc;
  sc.name = "collision";
  sc.thesis_video = "8";
  sc.description = "orange bottle slid at 0.1 m/s into a white cup; the bottle stops dead and the "
                   "cup tips over away from it";
  sc.scene = base_scene();
  sc.scene.objects = {object("bottle", "orange_bottle", 0.22, -0.2, Vector3d(0.9, 0.5, 0.15)),
                      object("cup", "white_cup", 0.22, 0.06, Vector3d(0.95, 0.95, 0.95))};
  const double speed = 0.004;                       // m per frame (0.1 m/s)
  const double contact_y = 0.06 - 0.035 - 0.040;    // bottle radius + cup rim radius
  const int impact = sc.still_frames + static_cast<int>(std::ceil((contact_y + 0.2) / speed));
  sc.frames = impact + 18;
  sc.pose = [sc, speed, contact_y, impact](sim::World& w, int k) {
    const double y = std::min(contact_y, -0.2 + speed * std::max(0, k - sc.still_frames));
    pose_base(w, 0, 0.22, y);
    // The cup tips about the far edge of its base, 90 deg in 10 frames (about 0.4 s).
    const double tau = std::max(0, k - impact);
    const double phi = 0.5 * M_PI * std::min(1.0, (tau / 10.0) * (tau / 10.0));
    const Quaterniond q = about(Vector3d::UnitX(), -phi);  // top falls towards +y
    const Vector3d pivot(0.22, 0.06 + 0.0285, 0);          // far edge of the base
    const Vector3d base = pivot + q * (Vector3d(0.22, 0.06, 0) - pivot);
    w.set_object_pose(1, base, q);
  };
  return sc;
}

Scenario l_path() {
  Scenario sc;
  sc.name = "l_path";
  sc.thesis_video = "10";
  sc.description = "pale glossy bottle slid along an L (towards the camera, then sharply sideways) "
                   "over a table of strongly coloured squares";
  sc.scene = base_scene();
  sc.scene.table.kind = sim::Appearance::Kind::Checker;
  sc.scene.table.colour = Vector3d(0.7, 0.3, 0.2);
  sc.scene.table.colour2 = Vector3d(0.25, 0.45, 0.7);
  sc.scene.table.repeat = 10;
  sim::ObjectSpec b = object("bottle", "pale_bottle", 0.05, -0.12, Vector3d(0.85, 0.88, 0.92));
  b.appearance.specular = 0.9;
  b.appearance.shininess = 0.9;
  sc.scene.objects = {b};
  sc.frames = 116;
  sc.pose = [sc](sim::World& w, int k) {
    const int leg1 = 45;
    const int m = std::max(0, k - sc.still_frames);
    if (m <= leg1) {
      pose_base(w, 0, 0.05 + 0.30 * m / leg1, -0.12);
    } else {
      pose_base(w, 0, 0.35, -0.12 + 0.28 * static_cast<double>(m - leg1) / (sc.frames - 1 - sc.still_frames - leg1));
    }
  };
  return sc;
}

Scenario cluttered_swing() {
  Scenario sc;
  sc.name = "cluttered_swing";
  sc.thesis_video = "-";
  sc.description = "ours: white cup carried in front of four cluttered objects (checkered table and wall, "
                   "shadows, noise sigma 2), bobbing and rocking +-25 deg";
  sc.scene = base_scene(2.0);
  sc.scene.table.kind = sim::Appearance::Kind::Checker;
  sc.scene.table.colour = Vector3d(0.75, 0.62, 0.45);
  sc.scene.table.colour2 = Vector3d(0.62, 0.50, 0.36);
  sc.scene.table.repeat = 12;
  sc.scene.background.kind = sim::Appearance::Kind::Checker;
  sc.scene.background.colour = Vector3d(0.25, 0.35, 0.6);
  sc.scene.background.colour2 = Vector3d(0.9, 0.88, 0.8);
  sc.scene.background.repeat = 10;
  sc.scene.render.shadows = true;
  sim::ObjectSpec mug = object("mug", "blue_mug", 0.32, 0.1, Vector3d(0.15, 0.3, 0.7));
  mug.yaw = -120 * kDeg;
  sim::ObjectSpec can = object("can", "silver_can", 0.30, -0.10, Vector3d(0.75, 0.75, 0.78));
  can.appearance.specular = 0.9;
  can.appearance.shininess = 0.8;
  sc.scene.objects = {object("cup", "white_cup", 0.45, 0.25, Vector3d(0.95, 0.95, 0.95)), mug,
                      checkered(object("bottle", "striped_bottle", 0.22, 0.0, Vector3d(0.1, 0.5, 0.2)),
                                Vector3d(0.9, 0.9, 0.9), 6),
                      can, object("bottle", "water_bottle", 0.18, -0.20, Vector3d(0.92, 0.92, 0.95))};
  sc.frames = 126;
  sc.pose = [sc](sim::World& w, int k) {
    const double s = progress(sc, k);
    const Vector3d c(0.40, 0.2 - 0.4 * s, 0.10 + 0.03 * std::sin(3 * M_PI * s));
    pose_centre(w, 0, c, about(view_axis(w, c), 25.0 * std::sin(2 * M_PI * s) * kDeg));
  };
  return sc;
}

}  // namespace

std::vector<Scenario> tracking_scenarios() {
  return {light_bottle_turning(), same_colour_occlusion(), cup_tilt(),  mug_behind_cup(),
          textured_bottle_scale(), multicolour_mug(),      collision(), crossing(),
          l_path(),                cluttered_swing()};
}

Video render_video(const Scenario& scenario, int camera, int max_frames) {
  sim::World world(scenario.scene);
  world.pusher_visible = false;
  world.park_pusher();
  const int n = max_frames > 0 ? std::min(max_frames, scenario.frames) : scenario.frames;
  Video video;
  Eigen::Vector3d last_pos = Eigen::Vector3d::Zero();
  Eigen::Quaterniond last_q = Eigen::Quaterniond::Identity();
  Stopwatch watch;
  for (int k = 0; k < n; ++k) {
    scenario.pose(world, k);
    VideoFrame f;
    f.image = world.render(camera);
    f.truth = world.axis_in_image(scenario.target, camera);
    const sim::ObjectState st = world.object(scenario.target);
    if (k > 0) {
      f.target_moving = (st.position - last_pos).norm() > 1e-6 || st.orientation.angularDistance(last_q) > 1e-6;
    }
    last_pos = st.position;
    last_q = st.orientation;
    if (k == 0) {
      const cv::Mat mask = world.render_mask(camera);
      video.first_mask = mask == scenario.target + 1;
      video.first_box = cv::boundingRect(video.first_mask);
      if (video.first_box.area() == 0) throw std::runtime_error(scenario.name + ": target not visible in frame 0");
    }
    video.frames.push_back(std::move(f));
  }
  video.render_ms = watch.elapsed_ms();
  return video;
}

double distance_to_line(const cv::Point2d& p, const sim::ImageLine& truth, int width, int height) {
  return std::abs(sim::signed_distance(truth, Eigen::Vector2d(p.x, p.y), width, height));
}

}  // namespace nudge::experiments
