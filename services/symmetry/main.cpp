// symmetry: detects bilateral symmetry lines in every image on its input channels and publishes
// them on the matching SYMMETRY_* channel (CAMERA_LEFT -> SYMMETRY_LEFT, CAMERA -> SYMMETRY).
#include <sstream>

#include "nudge/bus/image.hpp"
#include "nudge/bus/service.hpp"
#include "nudge/bus/symmetry_convert.hpp"
#include "nudge/image_t.hpp"
#include "nudge/log.hpp"
#include "nudge/symmetry/detector.hpp"

using namespace nudge;

namespace {

std::vector<std::string> split(const std::string& list) {
  std::vector<std::string> out;
  std::stringstream ss(list);
  for (std::string item; std::getline(ss, item, ',');)
    if (!item.empty()) out.push_back(item);
  return out;
}

std::string output_channel(const std::string& input) {
  const std::string prefix = "CAMERA";
  if (input.rfind(prefix, 0) == 0) return "SYMMETRY" + input.substr(prefix.size());
  return "SYMMETRY_" + input;
}

}  // namespace

int main(int argc, char** argv) {
  return bus::guarded_main("symmetry", [&] {
    bus::Service service("symmetry", "Fast bilateral symmetry detection (thesis ch. 3) on camera images.");
    symmetry::Params params;
    symmetry::EdgeParams edge;
    edge.blur_sigma = 1.0;  // thesis: Gaussian blur first on camera images
    std::string inputs = "CAMERA_LEFT,CAMERA_RIGHT";
    std::vector<double> canny = {edge.canny_low, edge.canny_high};
    auto& f = service.flags();
    f.add_string("inputs", &inputs, "comma-separated image channels");
    f.add_int("lines", &params.num_lines, "symmetry lines per image (Nlines)");
    f.add_double("dmin", &params.dmin, "minimum pairing distance, px");
    f.add_double("dmax", &params.dmax, "maximum pairing distance, px (0: none)");
    f.add_double("theta-min", &params.theta_min_deg, "orientation limit, degrees");
    f.add_double("theta-max", &params.theta_max_deg, "orientation limit, degrees");
    f.add_doubles("canny", &canny, 2, "Canny thresholds LOW HIGH");
    f.add_double("blur", &edge.blur_sigma, "Gaussian blur sigma before Canny (0: none)");
    f.add_double("min-peak-ratio", &params.min_peak_ratio, "drop peaks below this fraction of the top one");
    f.add_bool("once-per-row", &params.once_per_row, "a row of Rot increments a bin at most once");
    f.add_int("max-row-pixels", &params.max_row_pixels, "skip rows of Rot with more pixels (0: off)");
    f.add_int("threads", &params.threads, "threads across angles");
    if (!service.parse(argc, argv)) return 0;
    edge.canny_low = canny[0];
    edge.canny_high = canny[1];
    try {
      symmetry::validate(params);
      symmetry::validate(edge);
    } catch (const std::invalid_argument& e) {
      throw FlagError(e.what());
    }
    symmetry::Detector detector(params, edge);
    service.start();
    for (const auto& channel : split(inputs)) {
      const std::string out = output_channel(channel);
      service.subscriptions().subscribe<image_t>(channel, [&, out](const image_t& msg, const std::string&) {
        const cv::Mat image = bus::to_mat(msg);  // throws ImageError naming the image: counted, skipped
        const symmetry::Result result = detector.detect(image);
        service.publish(out, bus::to_message(result, msg.utime, msg.frame_id, msg.camera));
        log::debug() << out << " frame " << msg.frame_id << ": " << result.lines.size() << " lines, "
                     << result.num_edges << " edges, " << result.ms.total_ms() << " ms";
      });
      log::info() << channel << " -> " << out;
    }
    return service.run();
  });
}
