// The object-learning experiment's scenes (thesis sec. 7.4; issue 11; docs/sim.md):
//   nudge-exp-learning-scenes --out DIR [--set eval|dev] [--camera still|video] [--training-scenes DIR] [--report]
// renders the 28 test images (four per learned bottle: plain, cluttered, another orientation,
// partly occluded) and the 10 images of objects never learned, with the right camera, into
// DIR/NAME.png (colour), NAME_mask.png (object index + 1) and NAME_surface.png (object-surface
// coordinates, nudge/sim/truth_images.hpp), and DIR/manifest.json (what each image shows).
// --training-scenes writes the seven training scenes' YAML (experiments/scenes/learning/).
// --report writes docs/results/learning_scenes.{json,md} and a contact sheet of the test images.
#include "learning_scenes.hpp"

#include "nudge/atomic_file.hpp"
#include "nudge/flags.hpp"
#include "nudge/json.hpp"
#include "nudge/progress.hpp"
#include "nudge/sim/truth_images.hpp"
#include "report.hpp"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <chrono>
#include <filesystem>
#include <iostream>
#include <sstream>

using namespace nudge;
using namespace nudge::experiments;

namespace {

void write_image(const std::string& path, const cv::Mat& image) {
  if (!cv::imwrite(path, image)) throw std::runtime_error(path + ": cannot write");
}

std::string manifest(const std::vector<TestImage>& images, const std::string& set, const std::string& camera) {
  JsonWriter j(2);
  j.begin_object();
  const cv::Size size = images.empty() ? cv::Size() : images.front().colour.size();
  j.field("set", set).field("camera", "right " + camera).field("width", size.width).field("height", size.height);
  j.field("surface_encoding", "16-bit PNG, channel k = round((c + 0.5) * 65534) + 1, 0 = no object "
                              "(nudge::sim::decode_surface)");
  j.key("images").begin_array();
  for (const auto& t : images) {
    j.begin_object();
    j.field("name", t.name).field("target", t.target).field("variant", variant_name(t.variant));
    j.field("seed", static_cast<long long>(t.seed)).field("visible_fraction", t.visible_fraction);
    j.field("colour", t.name + ".png").field("mask", t.name + "_mask.png").field("surface", t.name + "_surface.png");
    j.key("objects").begin_array();
    for (size_t k = 0; k < t.scene.objects.size(); ++k) {
      const auto& o = t.scene.objects[k];
      j.begin_object().field("mask_label", static_cast<int>(k + 1)).field("name", o.name).field("kind", o.kind);
      j.field("label_picture", o.label.file.empty() ? o.mesh.texture : o.label.file).end_object();
    }
    j.end_array();
    j.end_object();
  }
  j.end_array();
  j.end_object();
  return j.str() + "\n";
}

void write_report(const std::vector<TestImage>& images, double seconds, const std::string& set) {
  std::vector<cv::Mat> thumbs;
  for (const auto& t : images) {
    cv::Mat small;
    cv::resize(t.colour, small, cv::Size(160, 120), 0, 0, cv::INTER_AREA);
    cv::putText(small, t.name.substr(0, 3), cv::Point(3, 12), cv::FONT_HERSHEY_PLAIN, 0.9, cv::Scalar(0, 0, 0), 1);
    thumbs.push_back(small);
  }
  // A JPEG: the sheet of 38 renders is 1.1 MB as a PNG, ~0.2 MB as a JPEG.
  std::vector<unsigned char> jpeg;
  cv::imencode(".jpg", tile(thumbs, 8), jpeg, {cv::IMWRITE_JPEG_QUALITY, 85});
  write_result("learning_scenes_" + set + ".jpg", std::string(jpeg.begin(), jpeg.end()));
  JsonWriter j(2);
  j.begin_object();
  j.field("machine", machine_description()).field("date", today()).field("set", set);
  j.field("test_images", static_cast<int>(images.size()) - 10).field("unknown_images", 10);
  j.field("seconds_to_generate", seconds);
  j.end_object();
  write_result("learning_scenes.json", j.str() + "\n");
  std::ostringstream md;
  md << "# The learning experiment's test images (`nudge-exp-learning-scenes --set " << set << "`)\n\n"
     << "Machine: " << machine_description() << ", " << today() << ". Generated in " << seconds
     << " s (rendering, masks and surface coordinates; retries included).\n\n"
     << "| image | target | variant | seed | visible |\n|---|---|---|---|---|\n";
  for (const auto& t : images)
    md << "| " << t.name << " | " << (t.target.empty() ? "(never learned)" : t.target) << " | "
       << variant_name(t.variant) << " | " << t.seed << " | " << static_cast<int>(100 * t.visible_fraction + 0.5)
       << " % |\n";
  md << "\n![test images](learning_scenes_" << set << ".jpg)\n";
  write_result("learning_scenes.md", md.str());
}

}  // namespace

int main(int argc, char** argv) {
  std::string out, set = "eval", training, camera = "still";
  bool report = false;
  Flags flags("nudge-exp-learning-scenes", "Render the object-learning experiment's test images and write its scenes.");
  flags.add_string("out", &out, "directory for the test images and manifest.json (made if missing)");
  flags.add_string("set", &set, "eval (the experiment's fixed seeds) or dev (another series, to tune on)");
  flags.add_string("camera", &camera, "the right camera's still (1280x960, the robot's close look) or video (640x480) image");
  flags.add_string("training-scenes", &training, "also write the seven training scenes' YAML into this directory");
  flags.add_bool("report", &report, "write docs/results/learning_scenes.{json,md} and a contact sheet");
  try {
    if (!flags.parse(argc, argv)) return 0;
    if (out.empty() && training.empty()) throw FlagError("--out or --training-scenes is needed");
    if (!training.empty()) {
      std::filesystem::create_directories(training);
      for (int i = 0; i < static_cast<int>(learning_bottles().size()); ++i) {
        const std::string path = training + "/train" + std::to_string(i + 1) + "_" + learning_bottles()[i].name + ".yaml";
        write_file_atomically(path, training_scene_yaml(i));
        sim::load_scene(path);  // what was written loads
        std::cerr << "wrote " << path << "\n";
      }
    }
    if (out.empty()) return 0;
    std::filesystem::create_directories(out);
    const auto start = std::chrono::steady_clock::now();
    nudge::Progress progress("nudge-exp-learning-scenes",
                             static_cast<int>(4 * learning_bottles().size() + unknown_objects(NUDGE_SOURCE_DIR).size()));
    const std::vector<TestImage> images = make_test_images(NUDGE_SOURCE_DIR, set, test_camera_from_name(camera),
                                                           [&](const std::string& name) { progress.step(name); });
    for (const auto& t : images) {
      write_image(out + "/" + t.name + ".png", t.colour);
      write_image(out + "/" + t.name + "_mask.png", t.mask);
      write_image(out + "/" + t.name + "_surface.png", sim::encode_surface(t.surface));
    }
    write_file_atomically(out + "/manifest.json", manifest(images, set, camera));
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    progress.clear_status();  // the report's "wrote" lines follow on stderr
    if (report) write_report(images, seconds, set);
    progress.finish("wrote " + std::to_string(images.size()) + " " + set + " images and manifest.json to " + out);
  } catch (const FlagError& e) {
    std::cerr << "nudge-exp-learning-scenes: " << e.what() << "\n" << flags.help();
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "nudge-exp-learning-scenes: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
