#include "tracking_scenarios.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <unistd.h>

#include <filesystem>
#include <iomanip>
#include <sstream>
#include <utility>

#include "nudge/sim/clutter.hpp"
#include "nudge/sim/objects.hpp"
#include "nudge/timing.hpp"

namespace nudge::experiments {

namespace {

using Eigen::Quaterniond;
using Eigen::Vector2d;
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

// ---- The scenario generator (issue 15): everything drawn from the seed.

class Draw {
 public:
  explicit Draw(uint64_t seed) : rng_(seed * 0x9E3779B97F4A7C15ULL + 15) {}
  double uniform(double lo, double hi) { return lo + (hi - lo) * rng_.uniform(0.0, 1.0); }
  int index(size_t n) { return rng_.uniform(0, static_cast<int>(n)); }
  bool chance(double p) { return rng_.uniform(0.0, 1.0) < p; }
  double sign() { return chance(0.5) ? 1.0 : -1.0; }
  // A colour of random hue, saturation and brightness (RGB in [0, 1]).
  Vector3d colour(double min_value = 0.25) {
    cv::Mat hsv(1, 1, CV_32FC3, cv::Scalar(uniform(0, 360), uniform(0, 0.9), uniform(min_value, 0.95)));
    cv::Mat rgb;
    cv::cvtColor(hsv, rgb, cv::COLOR_HSV2RGB);
    const cv::Vec3f c = rgb.at<cv::Vec3f>(0, 0);
    return Vector3d(c[0], c[1], c[2]);
  }

 private:
  cv::RNG rng_;
};

// Radius of an object's footprint seen from above (a mug's handle included).
double footprint(const std::string& kind) {
  return sim::make_object(kind, 12).max_radius + (kind == "mug" ? 0.02 : 0.0);
}

std::string stem(const std::string& path) { return std::filesystem::path(path).stem().string(); }

// The target's look; `what` gets a word for the description.
sim::ObjectSpec drawn_object(Draw& d, const std::string& kind, const std::string& name, std::string* what) {
  sim::ObjectSpec o = object(kind, name, 0.25, 0, d.colour());
  o.appearance.specular = d.uniform(0.1, 0.9);
  o.appearance.shininess = d.uniform(0.1, 0.9);
  const double look = d.uniform(0, 1);
  if (look < 0.4 || kind == "marker") {
    *what = "plain";
  } else if (look < 0.55) {
    o = checkered(o, d.colour(), d.index(5) + 4);
    *what = "checker";
  } else if (look < 0.7) {
    o = textured(o, "patches.png", d.index(2) + 1);
    o.appearance.colour = Vector3d(1, 1, 1);
    *what = "patches";
  } else {
    o.label.file = texture_file(d.chance(0.5) ? "label.png" : "patches.png");
    *what = "label " + stem(o.label.file);
  }
  return o;
}

sim::ObjectSpec plain_object(Draw& d, const std::string& name) {
  const auto kinds = sim::object_kinds();
  sim::ObjectSpec o = object(kinds[d.index(kinds.size())], name, 0, 0, d.colour());
  o.appearance.specular = d.uniform(0.1, 0.9);
  return o;
}

// A wall or table look: plain, checker or a photograph.
std::string draw_surface(Draw& d, sim::Appearance* a, const std::vector<std::string>& photographs,
                         double photo_share, double checker_share) {
  const double look = d.uniform(0, 1);
  if (look < photo_share) {
    a->kind = sim::Appearance::Kind::Image;
    a->file = photographs[d.index(photographs.size())];
    a->colour = Vector3d(1, 1, 1);
    a->repeat = d.index(3) + 1;
    return stem(a->file);
  }
  a->colour = d.colour(0.3);
  if (look < photo_share + checker_share) {
    a->kind = sim::Appearance::Kind::Checker;
    a->colour2 = d.colour(0.3);
    a->repeat = d.index(10) + 4;
    return "checker";
  }
  return "plain";
}

// Progress of a stop-and-go motion: three equal moves with two pauses of `pause` frames.
double stop_and_go(double s, int moving_frames, int pause) {
  const double p = std::clamp(static_cast<double>(pause) / std::max(1, moving_frames), 0.0, 0.3);
  const double move = (1.0 - 2 * p) / 3.0;
  if (s < move) return s / move / 3.0;
  if (s < move + p) return 1.0 / 3.0;
  if (s < 2 * move + p) return 1.0 / 3.0 + (s - move - p) / move / 3.0;
  if (s < 2 * move + 2 * p) return 2.0 / 3.0;
  return std::min(1.0, 2.0 / 3.0 + (s - 2 * move - 2 * p) / move / 3.0);
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


std::vector<std::string> generator_photographs(const std::string& directory) {
  // Chosen before any evaluation run; building, home, graf1, fruits and box are kept out (reserved
  // for the evaluation on photographs).
  const char* names[] = {"baboon.jpg",   "starry_night.jpg", "stuff.jpg",  "messi5.jpg",  "butterfly.jpg",
                         "board.jpg",    "smarties.png",     "aero3.jpg",  "leuvenA.jpg", "orange.jpg",
                         "rubberwhale1.png", "lena.jpg",     "HappyFish.jpg", "pic3.png", "sudoku.png"};
  std::vector<std::string> files;
  for (const char* name : names) {
    const std::string path = directory + "/" + name;
    if (!std::filesystem::exists(path)) continue;  // opencv-doc versions differ; at least 8 needed
    if (sim::is_reserved_picture(path)) throw std::logic_error(path + " is reserved for the evaluation on photographs");
    files.push_back(path);
  }
  if (files.size() < 8)
    throw std::runtime_error(directory + ": fewer than 8 of the generator's photographs found (Debian: opencv-doc)");
  return files;
}

Scenario generated_scenario(uint64_t seed, const std::vector<std::string>& photographs) {
  if (photographs.empty()) throw std::invalid_argument("generated_scenario: no photographs");
  Draw d(seed);
  Scenario sc;
  sc.name = "seed_" + std::to_string(seed);
  sc.thesis_video = "-";
  sc.scene = base_scene(d.uniform(0.5, 2.5));
  sc.scene.seed = seed;
  sc.scene.source = "generated_scenario " + std::to_string(seed);
  sc.scene.render.ambient = d.uniform(0.2, 0.5);
  sc.scene.render.light = d.uniform(0.35, 0.75);
  sc.scene.render.shadows = d.chance(0.5);
  const std::string wall = draw_surface(d, &sc.scene.background, photographs, 0.5, 0.2);
  const std::string table = draw_surface(d, &sc.scene.table, photographs, 0.3, 0.2);

  const auto kinds = sim::object_kinds();
  const std::string kind = kinds[d.index(kinds.size())];
  std::string look;
  sc.scene.objects = {drawn_object(d, kind, "target", &look)};
  sc.frames = 90 + d.index(41);
  const int moving_frames = sc.frames - 1 - sc.still_frames;

  // The path: from A on one side to B on the other (world y), at any depth x.
  const Vector3d a(d.uniform(0.1, 0.38), d.sign() * d.uniform(0.08, 0.2), 0);
  const Vector3d b(d.uniform(0.1, 0.38), -(a.y() / std::abs(a.y())) * d.uniform(0.05, 0.2), 0);
  const double height = sim::make_object(kind, 12).height;
  const char* paths[] = {"linear", "swing", "turning", "stop-and-go"};
  const int path = d.index(4);
  const double spin = d.uniform(-90, 90) * kDeg;                    // linear, stop-and-go: yaw turned
  const double lift = d.uniform(0.02, 0.06);                        // swing, turning: held up
  const double roll0 = d.uniform(-40, 40) * kDeg, roll = d.sign() * d.uniform(40, 100) * kDeg;
  const double amplitude = d.uniform(15, 35) * kDeg, cycles = d.uniform(1, 2.5);
  const double rod = d.uniform(0.12, 0.2);                          // swing: pendulum length
  const int pause = 8 + d.index(8);
  std::ostringstream what;
  what << kind << " (" << look << ") " << paths[path] << ", wall " << wall << ", table " << table;

  // Occluder in front of the middle of the path; distractor crossing behind (or, with no occluder,
  // in front). Both keep clear of the target's path by their radii and a gap.
  sc.scene.objects[0].position = a.head<2>();
  const double target_radius = footprint(kind);
  const bool occluded = d.chance(0.5);
  const double at = d.uniform(0.35, 0.65);
  sim::ObjectSpec occluder = plain_object(d, "occluder");
  const Vector3d occluder_at =
      a + at * (b - a) + Vector3d(target_radius + footprint(occluder.kind) + d.uniform(0.01, 0.03), d.uniform(-0.03, 0.03), 0);
  if (occluded) {
    occluder.position = occluder_at.head<2>();
    occluder.yaw = d.uniform(-M_PI, M_PI);
    sc.scene.objects.push_back(occluder);
    what << ", occluder " << occluder.kind;
  }
  const bool crossing = d.chance(0.5);
  sim::ObjectSpec crosser = plain_object(d, "distractor");
  const double side = !occluded && d.chance(0.3) ? 1.0 : -1.0;
  const double depth = side * (target_radius + footprint(crosser.kind) + d.uniform(0.01, 0.05));
  const int delay = d.index(26);
  const int distractor = static_cast<int>(sc.scene.objects.size());
  if (crossing) {
    crosser.position = Vector2d(b.x() + depth, b.y());
    sc.scene.objects.push_back(crosser);
    sc.distractor = distractor;
    what << ", " << crosser.kind << " crossing " << (depth < 0 ? "behind" : "in front") << " after " << delay << " frames";
  }
  // Static clutter further back, clear of each other.
  const int clutter = d.index(3);
  std::vector<std::pair<Vector2d, double>> standing;
  for (int i = 0; i < clutter; ++i) {
    sim::ObjectSpec o = plain_object(d, "clutter" + std::to_string(i));
    o.yaw = d.uniform(-M_PI, M_PI);
    const double r = footprint(o.kind);
    for (int attempt = 0; attempt < 50; ++attempt) {
      o.position = Vector2d(d.uniform(-0.35, -0.2), d.uniform(-0.3, 0.3));
      bool clear = true;
      for (const auto& [p, pr] : standing) clear = clear && (p - o.position).norm() > r + pr + 0.01;
      if (clear) {
        standing.emplace_back(o.position, r);
        sc.scene.objects.push_back(o);
        break;
      }
    }
  }
  if (standing.size() > 0) what << ", " << standing.size() << " behind";
  what << ", light " << std::setprecision(2) << sc.scene.render.ambient << "/" << sc.scene.render.light
       << (sc.scene.render.shadows ? " shadows" : "") << ", noise " << sc.scene.render.noise_sigma;
  sc.description = what.str();

  sc.pose = [sc, a, b, path, spin, lift, roll0, roll, amplitude, cycles, rod, pause, height, crossing, depth,
             delay, distractor, moving_frames](sim::World& w, int k) {
    const double s = progress(sc, k);
    const Vector3d along = a + s * (b - a);
    if (path == 0) {
      pose_base(w, 0, along.x(), along.y(), about(Vector3d::UnitZ(), spin * s));
    } else if (path == 1) {
      // A pendulum hung from a pivot carried from above A to above B.
      const Vector3d pivot = along + Vector3d(0, 0, rod + 0.5 * height + lift);
      const Quaterniond q = about(view_axis(w, pivot), amplitude * std::sin(2 * M_PI * cycles * s));
      pose_centre(w, 0, pivot + q * Vector3d(0, 0, -rod), q);
    } else if (path == 2) {
      const Vector3d c = along + Vector3d(0, 0, 0.5 * height + lift);
      pose_centre(w, 0, c, about(view_axis(w, c), roll0 + roll * ease(s)));
    } else {
      const Vector3d p = a + stop_and_go(s, moving_frames, pause) * (b - a);
      pose_base(w, 0, p.x(), p.y(), about(Vector3d::UnitZ(), spin * stop_and_go(s, moving_frames, pause)));
    }
    if (crossing) {
      Scenario later = sc;
      later.still_frames = sc.still_frames + delay;
      const Vector3d p = b + progress(later, k) * (a - b) + Vector3d(depth, 0, 0);
      pose_base(w, distractor, p.x(), p.y());
    }
  };
  return sc;
}

std::array<Video, 2> render_stereo_video(const Scenario& scenario, int max_frames) {
  sim::World world(scenario.scene);
  world.pusher_visible = false;
  world.park_pusher();
  const int n = max_frames > 0 ? std::min(max_frames, scenario.frames) : scenario.frames;
  std::array<Video, 2> videos;
  Eigen::Vector3d last_pos = Eigen::Vector3d::Zero();
  Eigen::Quaterniond last_q = Eigen::Quaterniond::Identity();
  Stopwatch watch;
  for (int k = 0; k < n; ++k) {
    scenario.pose(world, k);
    const sim::StereoImages images = world.render_stereo(/*masks=*/true);
    const sim::ObjectState st = world.object(scenario.target);
    const bool moving =
        k > 0 && ((st.position - last_pos).norm() > 1e-6 || st.orientation.angularDistance(last_q) > 1e-6);
    last_pos = st.position;
    last_q = st.orientation;
    for (int camera = 0; camera < 2; ++camera) {
      VideoFrame f;
      f.image = images.colour[camera];
      f.target_mask = images.mask[camera] == scenario.target + 1;
      if (scenario.distractor >= 0) f.distractor_mask = images.mask[camera] == scenario.distractor + 1;
      f.truth = world.axis_in_image(scenario.target, camera);
      f.target_moving = moving;
      Video& video = videos[camera];
      if (k == 0) {
        video.first_mask = f.target_mask.clone();
        video.first_box = cv::boundingRect(video.first_mask);
        if (video.first_box.area() == 0)
          throw std::runtime_error(scenario.name + ": target not visible in frame 0 of camera " + std::to_string(camera));
      }
      video.frames.push_back(std::move(f));
    }
  }
  videos[0].render_ms = videos[1].render_ms = 0.5 * watch.elapsed_ms();
  return videos;
}

double distance_to_line(const cv::Point2d& p, const sim::ImageLine& truth, int width, int height) {
  return std::abs(sim::signed_distance(truth, Eigen::Vector2d(p.x, p.y), width, height));
}

}  // namespace nudge::experiments
