#include "fuzz_targets.hpp"

#include <unistd.h>

#include <cstdio>
#include <new>
#include <stdexcept>

#include "nudge/arm_command_t.hpp"
#include "nudge/arm_state_t.hpp"
#include "nudge/axes_t.hpp"
#include "nudge/bus/decode.hpp"
#include "nudge/bus/image.hpp"
#include "nudge/candidates_request_t.hpp"
#include "nudge/candidates_t.hpp"
#include "nudge/geometry/stereo_rig.hpp"
#include "nudge/heartbeat_t.hpp"
#include "nudge/image_t.hpp"
#include "nudge/learn_result_t.hpp"
#include "nudge/recognition_t.hpp"
#include "nudge/robot/workspace.hpp"
#include "nudge/sim_state_t.hpp"
#include "nudge/snapshot_request_t.hpp"
#include "nudge/supervisor_state_t.hpp"
#include "nudge/symmetry/detector.hpp"
#include "nudge/symmetry_lines_t.hpp"
#include "nudge/track_t.hpp"
#include "nudge/tracker_command_t.hpp"
#ifdef NUDGE_FUZZ_HAVE_SIM
#include "nudge/sim/scene.hpp"
#endif

namespace nudge::fuzz {

namespace {

template <typename Msg>
void decode_as(const uint8_t* data, size_t size) {
  Msg msg;
  (void)bus::decode_message(data, static_cast<int>(size), &msg);  // "" or why not: both fine
}

// Writes the bytes to a file of this process's own (the readers take paths) and returns its path.
std::string as_file(const uint8_t* data, size_t size, const char* suffix) {
  const std::string path = "/tmp/nudge_fuzz_" + std::to_string(::getpid()) + suffix;
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) throw std::logic_error("cannot write " + path);
  std::fwrite(data, 1, size, f);
  std::fclose(f);
  return path;
}

// Runs a file reader: the errors it documents (std::runtime_error and kin, naming the file) are
// the expected answer to garbage; running out of memory is not.
template <typename Read>
int read_file(const uint8_t* data, size_t size, const char* suffix, Read read) {
  const std::string path = as_file(data, size, suffix);
  try {
    read(path);
  } catch (const std::bad_alloc&) {
    throw;
  } catch (const std::exception&) {
  }
  ::unlink(path.c_str());
  return 0;
}

}  // namespace

int fuzz_messages(const uint8_t* data, size_t size) {
  decode_as<arm_command_t>(data, size);
  decode_as<arm_state_t>(data, size);
  decode_as<axes_t>(data, size);
  decode_as<candidates_request_t>(data, size);
  decode_as<candidates_t>(data, size);
  decode_as<heartbeat_t>(data, size);
  decode_as<learn_result_t>(data, size);
  decode_as<recognition_t>(data, size);
  decode_as<sim_state_t>(data, size);
  decode_as<snapshot_request_t>(data, size);
  decode_as<supervisor_state_t>(data, size);
  decode_as<symmetry_lines_t>(data, size);
  decode_as<track_t>(data, size);
  decode_as<tracker_command_t>(data, size);
  image_t image;
  if (bus::decode_message(data, static_cast<int>(size), &image).empty()) {
    try {
      bus::to_mat(image);
    } catch (const bus::ImageError&) {
    }
  }
  return 0;
}

int fuzz_image(const uint8_t* data, size_t size) {
  for (const int8_t format : {image_t::FORMAT_PNG, image_t::FORMAT_MJPEG}) {
    image_t image;
    image.camera = "fuzz";
    image.pixel_format = format;
    image.data.assign(data, data + size);
    image.size = static_cast<int32_t>(size);
    try {
      bus::to_mat(image);
    } catch (const bus::ImageError&) {
    }
  }
  return 0;
}

int fuzz_calibration(const uint8_t* data, size_t size) {
  return read_file(data, size, "_rig.yaml", [](const std::string& path) { geometry::load_rig(path); });
}

int fuzz_workspace(const uint8_t* data, size_t size) {
  return read_file(data, size, "_workspace.yaml", [](const std::string& path) { robot::load_workspace(path); });
}

#ifdef NUDGE_FUZZ_HAVE_SIM
int fuzz_scene(const uint8_t* data, size_t size) {
  return read_file(data, size, "_scene.yaml", [](const std::string& path) { sim::load_scene(path); });
}
#endif

int fuzz_detector(const uint8_t* data, size_t size) {
  if (size < 8) return 0;
  symmetry::Params params;
  params.dmin = data[2] % 40;
  params.dmax = data[3] == 0 ? 0 : params.dmin + data[3];
  params.theta_min_deg = static_cast<int>(data[4] % 181) - 90;
  params.theta_max_deg = static_cast<int>(data[5] % 181) - 90;
  params.num_lines = 1 + data[6] % 6;
  params.once_per_row = data[7] & 1;
  params.max_row_pixels = (data[7] & 2) ? 4 : 0;
  params.anti_alias = data[7] & 4;
  params.refine_log = !(data[7] & 8);
  try {
    symmetry::validate(params);
  } catch (const std::invalid_argument&) {
    return 0;  // refused by the documented check, as a service's flags would be
  }
  symmetry::EdgeSet edges;
  edges.width = 1 + data[0] % 96;
  edges.height = 1 + data[1] % 96;
  for (size_t i = 8; i + 1 < size; i += 2)
    edges.points.emplace_back(data[i] % edges.width, data[i + 1] % edges.height);
  symmetry::Detector detector(params);
  const symmetry::Result result = detector.detect(edges);
  if (static_cast<int>(result.lines.size()) > params.num_lines) __builtin_trap();  // a broken promise
  return 0;
}

const std::vector<Target>& targets() {
  static const std::vector<Target> all = {
      {"messages", fuzz_messages},   {"image", fuzz_image},       {"calibration", fuzz_calibration},
      {"workspace", fuzz_workspace}, {"detector", fuzz_detector},
#ifdef NUDGE_FUZZ_HAVE_SIM
      {"scene", fuzz_scene},
#endif
  };
  return all;
}

}  // namespace nudge::fuzz
