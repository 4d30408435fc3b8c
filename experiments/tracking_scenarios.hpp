#pragma once
// The ten tracking test videos of thesis sec. 5.3, re-staged in the simulated world with exact
// ground truth. Objects are moved kinematically (World::set_object_pose, no physics) one frame
// at a time at 25 Hz; each video starts with a few still frames so that the tracker's automatic
// start sees a sharp jump in motion, as in the thesis' hand-held videos.
//
//   for (const Scenario& s : tracking_scenarios()) {
//     const Video v = render_video(s, /*camera=*/0);
//     for (const VideoFrame& f : v.frames) ... f.image (BGR 640x480), f.truth (R, theta of the target)
//   }
#include <opencv2/core.hpp>

#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "nudge/sim/world.hpp"

namespace nudge::experiments {

struct Scenario {
  std::string name;          // short id, e.g. "light_bottle_turning"
  std::string description;   // one line: what moves and what makes it hard
  std::string thesis_video;  // the thesis video it re-stages ("1".."10", or "-" for ours)
  sim::Scene scene;
  int target = 0;            // index of the tracked object
  int frames = 0;            // total frames
  int still_frames = 6;      // frames before anything moves
  int distractor = -1;       // index of an object that crosses the target's path (-1: none)
  // Sets the pose of every moving object for frame k (0 .. frames - 1).
  std::function<void(sim::World& world, int k)> pose;
};

struct VideoFrame {
  cv::Mat image;             // BGR, the rig's size (640x480)
  cv::Mat target_mask;       // CV_8U 255 on the target's visible pixels (render_stereo_video only)
  cv::Mat distractor_mask;   // CV_8U 255 on the crossing distractor's pixels (render_stereo_video; empty: none)
  sim::ImageLine truth;      // the target's axis in this camera
  bool target_moving = false;// the target's pose differs from the previous frame's
};

struct Video {
  std::vector<VideoFrame> frames;
  cv::Rect first_box;        // bounding box of the target's mask in frame 0
  cv::Mat first_mask;        // CV_8U 255 on the target's pixels in frame 0
  double render_ms = 0;      // total rendering time
};

// The ten scenarios (thesis videos 1-9 re-staged, plus one of ours), in a fixed order.
std::vector<Scenario> tracking_scenarios();

// Renders a scenario from camera `camera` (0 = left). max_frames > 0 shortens the video.
Video render_video(const Scenario& scenario, int camera = 0, int max_frames = 0);

// Both cameras' videos of a scenario from one pass of the world, each frame with the target's
// true mask (target_mask). max_frames > 0 shortens the videos.
std::array<Video, 2> render_stereo_video(const Scenario& scenario, int max_frames = 0);

// A scenario drawn from `seed` (issue 15's evaluation videos, never re-staged): the target is any
// object kind of the simulator (one size per kind: its size in the image varies with its distance
// from the camera) in a random colour, checker, printed texture or wrapped label; it moves along a
// linear, swing (pendulum), turning (held up and rolled) or stop-and-go path; a static occluder
// in front of the middle of its path, a distractor crossing behind or in front of it, static
// clutter behind; a plain, checkered or photographed wall and table; ambient and diffuse light,
// shadows and sensor noise drawn too. `photographs`: pictures for walls and tables (none of
// sim::is_reserved_picture's). Same seed, same pictures: the same scenario.
Scenario generated_scenario(uint64_t seed, const std::vector<std::string>& photographs);

// The photographs the generator uses, fixed in advance: opencv-doc pictures in `directory`
// (Debian: /usr/share/doc/opencv-doc/examples/data), none of them reserved for the evaluation on
// photographs. Throws std::runtime_error naming a missing file.
std::vector<std::string> generator_photographs(const std::string& directory);

// Distance (px) from an image point to the true line.
double distance_to_line(const cv::Point2d& p, const sim::ImageLine& truth, int width, int height);

}  // namespace nudge::experiments
