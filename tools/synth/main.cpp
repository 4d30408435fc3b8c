// nudge-synth-scenes: writes synthetic indoor-like frames (symmetric objects, clutter, noise) as
// PNG files: a deterministic image sequence for demos, tests and benchmarks.
#include <opencv2/imgcodecs.hpp>

#include <cstdio>
#include <iostream>
#include <sys/stat.h>

#include "nudge/flags.hpp"
#include "nudge/symmetry/synthetic.hpp"

int main(int argc, char** argv) {
  std::string out_dir = "out/scenes";
  int count = 10, seed = 1, width = 640, height = 480, clutter = 3;
  nudge::Flags flags("nudge-synth-scenes", "Writes synthetic indoor-like frames DIR/frame_NNN.png.");
  flags.add_string("out", &out_dir, "output directory (created)");
  flags.add_int("count", &count, "number of frames");
  flags.add_int("seed", &seed, "first seed; frame i uses seed + i");
  flags.add_int("width", &width, "frame width");
  flags.add_int("height", &height, "frame height");
  flags.add_int("clutter", &clutter, "amount of background clutter (0..10)");
  try {
    if (!flags.parse(argc, argv)) return 0;
    if (count < 0 || width < 16 || height < 16 || width > 8192 || height > 8192 || clutter < 0 || clutter > 10) {
      throw nudge::FlagError("--count >= 0, --width/--height in [16, 8192], --clutter in [0, 10]");
    }
  } catch (const std::exception& e) {
    std::cerr << "nudge-synth-scenes: " << e.what() << "\n";
    return 2;
  }
  ::mkdir(out_dir.c_str(), 0755);
  for (int i = 0; i < count; ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "/frame_%03d.png", i);
    const cv::Mat img = nudge::symmetry::synthetic::indoor_scene(static_cast<uint32_t>(seed + i), width, height, clutter);
    if (!cv::imwrite(out_dir + name, img)) {
      std::cerr << "nudge-synth-scenes: cannot write " << out_dir << name << "\n";
      return 1;
    }
  }
  std::cout << "wrote " << count << " frames to " << out_dir << "\n";
  return 0;
}
