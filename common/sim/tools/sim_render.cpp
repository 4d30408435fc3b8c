// nudge-sim-render: builds the simulated world of a scene file, renders the stereo pair (and the
// segmentation masks) and writes them as PNGs; prints the timing of each phase.
//   nudge-sim-render common/sim/scenes/three_objects.yaml --out /tmp/sim --steps 0
#include "nudge/flags.hpp"
#include "nudge/log.hpp"
#include "nudge/sim/truth_images.hpp"
#include "nudge/sim/world.hpp"
#include "nudge/timing.hpp"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <iostream>

namespace {
void write_png(const std::string& path, const cv::Mat& image) {
  if (!cv::imwrite(path, image)) throw std::runtime_error(path + ": cannot write the image");
}
}  // namespace

int main(int argc, char** argv) {
  nudge::log::set_component("sim-render");
  std::string out = ".";
  double seconds = 0;
  int repeat = 5;
  bool masks = false, axes = false, mjcf = false, surface = false;
  nudge::Flags flags("nudge-sim-render", "Render a scene's stereo pair to PNG files.");
  flags.set_positional("SCENE", "scene file (YAML)");
  flags.add_string("out", &out, "output directory (must exist)");
  flags.add_double("seconds", &seconds, "simulate this long before rendering");
  flags.add_int("repeat", &repeat, "render the pair this many times for timing");
  flags.add_bool("masks", &masks, "also write the segmentation masks (object index + 1, scaled)");
  flags.add_bool("axes", &axes, "also write images with the ground-truth symmetry axes drawn");
  flags.add_bool("mjcf", &mjcf, "also write the generated MuJoCo model as world.xml");
  flags.add_bool("surface", &surface,
                 "also write each pixel's object-surface coordinates (16-bit PNG, nudge/sim/truth_images.hpp)");
  try {
    if (!flags.parse(argc, argv)) return 0;
    if (flags.positional().size() != 1) throw nudge::FlagError("expected one SCENE file");
    if (repeat < 1) throw nudge::FlagError("--repeat must be >= 1");
    // Checked before the slow part, and not created: a typo should not scatter files.
    if (!std::filesystem::is_directory(out)) throw nudge::FlagError("--out " + out + ": no such directory (create it first)");
  } catch (const nudge::FlagError& e) {
    std::cerr << e.what() << "\n" << flags.help();
    return 2;
  }
  try {
    nudge::Stopwatch watch;
    const nudge::sim::Scene scene = nudge::sim::load_scene(flags.positional()[0]);
    const double load_ms = watch.lap_ms();
    nudge::sim::World world(scene);
    const double build_ms = watch.lap_ms();
    world.step_for(seconds);
    const double step_ms = watch.lap_ms();
    nudge::sim::StereoImages first = world.render_stereo(masks);
    const double first_ms = watch.lap_ms();
    for (int i = 1; i < repeat; ++i) world.render_stereo(false);
    const double pair_ms = repeat > 1 ? watch.lap_ms() / (repeat - 1) : first_ms;
    cv::Mat still[2];
    for (int c = 0; c < 2; ++c) still[c] = world.render_snapshot(c);
    const double still_ms = watch.lap_ms();
    double mask_ms = 0;
    if (masks) {
      for (int i = 0; i < repeat; ++i) world.render_mask(0);
      mask_ms = watch.lap_ms() / repeat;
    }
    const char* names[2] = {"left", "right"};
    for (int c = 0; c < 2; ++c) {
      write_png(out + "/" + names[c] + ".png", first.colour[c]);
      write_png(out + "/" + names[c] + "_still.png", still[c]);
      if (masks) {
        cv::Mat scaled;
        first.mask[c].convertTo(scaled, CV_8U, 255.0 / std::max(1, world.num_objects()));
        write_png(out + "/" + names[c] + "_mask.png", scaled);
      }
      if (surface)
        cv::imwrite(out + "/" + names[c] + "_surface.png", nudge::sim::encode_surface(world.render_surface(c)));
      if (axes) {
        cv::Mat drawn = first.colour[c].clone();
        for (int i = 0; i < world.num_objects(); ++i) {
          const auto line = world.axis_in_image(i, c);
          if (!line.valid) continue;
          cv::line(drawn, cv::Point2d(line.bottom.x(), line.bottom.y()),
                   cv::Point2d(line.top.x(), line.top.y()), cv::Scalar(0, 0, 255), 1, cv::LINE_AA);
        }
        write_png(out + "/" + names[c] + "_axes.png", drawn);
      }
    }
    if (mjcf) {
      std::FILE* f = std::fopen((out + "/world.xml").c_str(), "w");
      bool written = f && std::fputs(world.mjcf().c_str(), f) >= 0;
      if (f && std::fclose(f) != 0) written = false;
      if (!written)
        throw std::runtime_error(out + "/world.xml: cannot write the model");
    }
    std::printf("scene %s: %d objects, %dx%d\n", scene.source.c_str(), world.num_objects(),
                scene.rig.width, scene.rig.height);
    std::printf("load %.1f ms, build+settle %.1f ms, simulate %.2f s in %.1f ms\n", load_ms,
                build_ms, seconds, step_ms);
    std::printf("first stereo pair (incl. GL context%s) %.1f ms; stereo pair %.1f ms (%.1f per camera)",
                masks ? " and masks" : "", first_ms, pair_ms, pair_ms / 2);
    if (masks) std::printf("; mask %.1f ms", mask_ms);
    std::printf("\nhigh-resolution still pair %dx%d %.1f ms\n", still[0].cols, still[0].rows, still_ms);
    for (int i = 0; i < world.num_objects(); ++i) {
      const auto st = world.object(i);
      for (int c = 0; c < 2; ++c) {
        const auto line = world.axis_in_image(i, c);
        std::printf("  %-10s %-6s at (%.3f, %.3f, %.4f) tilt %.2f deg  %s R %.1f px theta %.2f deg\n",
                    st.name.c_str(), st.kind.c_str(), st.position.x(), st.position.y(),
                    st.position.z(), st.tilt() * 180 / M_PI, names[c], line.r,
                    line.theta * 180 / M_PI);
      }
    }
  } catch (const std::exception& e) {
    nudge::log::error() << e.what();
    return 1;
  }
  return 0;
}
