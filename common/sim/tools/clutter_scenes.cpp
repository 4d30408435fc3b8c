// nudge-clutter-scenes: writes the busy-table scene family of issue 14 (nudge/sim/clutter.hpp):
// the photographs it uses as PNG textures (MuJoCo reads PNG only) and one scene file per seed.
//   nudge-clutter-scenes --out common/sim/scenes/clutter --prefix dev 1 2 3
#include "nudge/flags.hpp"
#include "nudge/sim/clutter.hpp"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <filesystem>
#include <fstream>
#include <iostream>

namespace fs = std::filesystem;

namespace {

// opencv-doc's pictures (none of the ones kept for evaluation on photographs).
const std::vector<std::string> kBackdrops = {"starry_night.jpg", "baboon.jpg", "stuff.jpg", "messi5.jpg", "aero3.jpg"};
const std::vector<std::string> kTables = {"board.jpg", "orange.jpg", "smarties.png", "sudoku.png", "ela_original.jpg"};

// The picture as a PNG of at most 320 px a side in `dir`; returns its absolute path.
std::string texture(const std::string& pictures, const std::string& name, const std::string& dir) {
  const std::string out = fs::absolute(fs::path(dir) / (fs::path(name).stem().string() + ".png")).string();
  if (fs::exists(out)) return out;
  cv::Mat image = cv::imread(pictures + "/" + name, cv::IMREAD_COLOR);
  if (image.empty()) throw std::runtime_error("cannot read picture " + pictures + "/" + name);
  const double scale = 320.0 / std::max(image.cols, image.rows);
  if (scale < 1) cv::resize(image, image, cv::Size(), scale, scale, cv::INTER_AREA);
  const std::string tmp = out + ".tmp.png";
  if (!cv::imwrite(tmp, image)) throw std::runtime_error("cannot write " + tmp);
  fs::rename(tmp, out);  // never a half-written texture
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  std::string out, prefix = "scene", pictures = "/usr/share/doc/opencv-doc/examples/data";
  nudge::Flags flags("nudge-clutter-scenes", "Write seeded busy-table scenes (issue 14) and their PNG textures.");
  flags.add_string("out", &out, "output directory (created; textures go to OUT/textures)");
  flags.add_string("prefix", &prefix, "scene file names: PREFIX_SEED.yaml");
  flags.add_string("pictures", &pictures, "directory of opencv-doc's example pictures");
  flags.set_positional("SEED...", "one scene per seed");
  try {
    if (!flags.parse(argc, argv)) return 0;
    if (out.empty()) throw nudge::FlagError("--out DIR is required");
    if (flags.positional().empty()) throw nudge::FlagError("expected at least one SEED");
  } catch (const nudge::FlagError& e) {
    std::cerr << e.what() << "\n" << flags.help();
    return 2;
  }
  try {
    fs::create_directories(fs::path(out) / "textures");
    nudge::sim::ClutterOptions options;
    for (const auto& name : kBackdrops) options.backdrops.push_back(texture(pictures, name, out + "/textures"));
    for (const auto& name : kTables) options.tables.push_back(texture(pictures, name, out + "/textures"));
    for (const std::string& seed : flags.positional()) {
      if (seed.empty() || seed.find_first_not_of("0123456789") != std::string::npos)
        throw std::runtime_error("SEED: not a non-negative integer: '" + seed + "'");
      const uint64_t s = std::stoull(seed);
      const nudge::sim::Scene scene = nudge::sim::clutter_scene(s, options);
      const std::string file = out + "/" + prefix + "_" + std::to_string(s) + ".yaml";
      std::ofstream(file + ".tmp") << nudge::sim::scene_yaml(
          scene, "Busy table of issue 14, written by nudge-clutter-scenes " + seed +
                     " (format: docs/sim.md).", fs::absolute(out).string());
      fs::rename(file + ".tmp", file);
      std::cout << file << ": " << scene.objects.size() << " objects\n";
    }
  } catch (const std::exception& e) {
    std::cerr << "nudge-clutter-scenes: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
