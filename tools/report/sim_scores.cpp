#include "sim_scores.hpp"

#include <lcm/lcm-cpp.hpp>
#include <opencv2/imgproc.hpp>

#include <map>
#include <stdexcept>

#include "nudge/bus/channels.hpp"
#include "nudge/bus/decode.hpp"
#include "nudge/bus/image.hpp"
#include "nudge/bus/sim_convert.hpp"
#include "nudge/segmentation_t.hpp"
#include "nudge/sim/mask_score.hpp"
#include "nudge/sim/state_sync.hpp"
#include "nudge/sim/world.hpp"
#include "nudge/sim_state_t.hpp"
#include "nudge/supervisor_state_t.hpp"

namespace nudge::report {

namespace {
constexpr int kRightCamera = 1;  // the supervisor segments the right camera's stills
}

std::vector<viewer::SimulationScore> simulation_scores(const std::string& log_path, const std::string& scene_file) {
  sim::Scene scene = sim::load_scene(scene_file);
  scene.render.noise_sigma = 0;  // the truth, not a camera's view of it
  const int objects = static_cast<int>(scene.objects.size());
  sim::World world(scene);
  lcm::LogFile log(log_path, "r");
  if (!log.good()) throw std::runtime_error("cannot read the run's LCM log " + log_path);
  std::vector<viewer::SimulationScore> scores;
  // The world's states by simulated time. The supervisor publishes SEGMENTATION when the attempt
  // ends: with learning, after the object was grasped, turned and put back (or dropped). Its stamp
  // is the after still's time now, but logs recorded before that fix carry the attempt's end. So
  // the mask is scored against the world as it was when segmentation began (the supervisor's
  // SEGMENT state, right after the after still, the arm parked and the object at rest), and
  // against the segmentation's own stamp only when the log has no SEGMENT state.
  std::map<int64_t, sim::PoseSnapshot> states;
  std::map<int, int64_t> segment_started;  // attempt -> the supervisor's SEGMENT transition
  while (const lcm::LogEvent* e = log.readNextEvent()) {
    const int size = static_cast<int>(e->datalen);
    if (e->channel == bus::channel::SIM_STATE) {
      sim_state_t state;
      if (bus::decode_message(e->data, size, &state).empty()) states[state.utime] = bus::poses_of(state);
    } else if (e->channel == bus::channel::SUPERVISOR_STATE) {
      supervisor_state_t state;
      if (bus::decode_message(e->data, size, &state).empty() && state.state_name == "SEGMENT")
        segment_started.emplace(state.attempt, state.utime);  // the first: the transition
    } else if (e->channel == bus::channel::SEGMENTATION) {
      segmentation_t seg;
      if (!bus::decode_message(e->data, size, &seg).empty()) continue;
      const auto started = segment_started.find(seg.attempt);
      auto at_still = states.upper_bound(started != segment_started.end() ? started->second : seg.utime);
      if (at_still == states.begin()) continue;  // no state of the world before the still
      --at_still;
      cv::Mat mask = bus::to_mat(seg.mask);
      if (mask.channels() > 1) cv::cvtColor(mask, mask, cv::COLOR_BGR2GRAY);
      sim::apply_poses(world, at_still->second);
      const cv::Mat labels = world.render_snapshot_mask(kRightCamera);
      if (mask.size() != labels.size())
        throw std::runtime_error(log_path + ": attempt " + std::to_string(seg.attempt) + "'s mask is " +
                                 std::to_string(mask.cols) + "x" + std::to_string(mask.rows) + ", the scene's still " +
                                 std::to_string(labels.cols) + "x" + std::to_string(labels.rows) + " (another scene?)");
      const sim::MaskScore m = sim::score_mask(mask, labels, objects);
      viewer::SimulationScore s;
      s.attempt = seg.attempt;
      s.object = m.object;
      if (m.object >= 0) s.object_name = scene.objects[m.object].name;
      s.iou = m.iou;
      scores.push_back(s);
    }
  }
  return scores;
}

}  // namespace nudge::report

