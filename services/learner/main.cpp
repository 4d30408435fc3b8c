// learner: learns objects from the training views the supervisor sends (LEARN_VIEW, LEARN_COMMIT
// -> LEARNED), keeps them in the object database (--db), and says which known object an image
// shows (RECOGNIZE_REQUEST -> RECOGNITION). Thesis ch. 7; docs/learning.md.
#include "learner/handlers.hpp"
#include "nudge/bus/service.hpp"
#include "nudge/flags.hpp"

using namespace nudge;

int main(int argc, char** argv) {
  return bus::guarded_main("learner", [&] {
    bus::Service service("learner", "Object learning from training views and recognition (thesis ch. 7).");
    learner_service::Options options;
    std::string matcher = learning::matcher_name(options.recognize.matcher);
    auto& f = service.flags();
    f.add_string("db", &options.db_dir, "the object database's folder (created if missing); required");
    f.add_string("matcher", &matcher, "descriptor matching: shared-flann (one index for the database), flann or bf (per object); docs/benchmarks.md");
    f.add_double("ratio", &options.recognize.ratio, "recognition's ratio test: d1 < RATIO * d2 (thesis 0.6, Lowe 0.8; docs/learning.md)");
    f.add_int("min-matches", &options.recognize.min_matches, "verified matches the best object needs (thesis 3)");
    f.add_double("colour-tolerance", &options.recognize.colour_tolerance,
                 "recognition's ratio test by colour: a candidate's chromaticity within this of the query keypoint's; 0 off (docs/learning.md)");
    f.add_double("ransac-px", &options.recognize.ransac_px, "geometric check: inlier distance, pixels");
    f.add_double("distinct-place-px", &options.recognize.distinct_place_px,
                 "geometric check: matches whose training keypoints lie within this many pixels are one place; a mapping needs 4 places (0: each match one)");
    f.add_double("box-margin", &options.learn.box_margin, "training box grown by this fraction each side");
    f.add_int("background-matches", &options.learn.background_matches,
              "a descriptor matching this many other views is background (thesis 3)");
    f.add_double("background-static-px", &options.learn.background_static_px,
                 "... where a match counts only within this many pixels of the descriptor: the scene stands still (0: anywhere, as the thesis)");
    f.add_double("mask-support", &options.learn.mask_support,
                 "a view sent with its object's mask keeps the keypoints whose disc, this many times SIFT's radius, lies inside it (0: the centre)");
    f.add_double("sift-contrast", &options.recognize.sift.contrast_threshold,
                 "SIFT's contrast threshold, learning and recognition (OpenCV's default 0.04; lower finds more on small labels)");
    f.add_double("sift-equalise", &options.recognize.sift.equalise_clip,
                 "local contrast equalisation (CLAHE clip limit) before SIFT, learning and recognition; 0: none");
    std::string axis_tilts = learning::axis_tilts_text(options.learn.axis_tilts);
    f.add_string("axis-tilts", &axis_tilts,
                 "also learn each view squeezed along the held object's axis by these simulated tilts (1/cos: 2 = 60 deg), comma-separated; \"\": none");
    std::string tilts_as_fallback = options.recognize.tilts_as_fallback ? "on" : "off";
    f.add_string("tilts-as-fallback", &tilts_as_fallback,
                 "on|off: the features learned at --axis-tilts matched only when the views as taken recognise nothing");
    f.add_double("view-expiry", &options.view_expiry_s, "drop views not committed within SECONDS of message time");
    if (!service.parse(argc, argv)) return 0;
    if (options.db_dir.empty()) throw FlagError("--db DIR is required");
    try {
      options.recognize.matcher = learning::matcher_from_name(matcher);
    } catch (const std::invalid_argument& e) {
      throw FlagError(std::string("--matcher: ") + e.what());
    }
    if (options.recognize.ratio <= 0 || options.recognize.ratio > 1) throw FlagError("--ratio must be in (0, 1]");
    if (options.recognize.min_matches < 1) throw FlagError("--min-matches must be >= 1");
    if (options.learn.background_matches < 1) throw FlagError("--background-matches must be >= 1");
    if (!(options.learn.mask_support >= 0)) throw FlagError("--mask-support must be >= 0");
    try {
      options.learn.axis_tilts = learning::axis_tilts_from_text(axis_tilts);
    } catch (const std::invalid_argument& e) {
      throw FlagError(std::string("--axis-tilts: ") + e.what());
    }
    if (tilts_as_fallback != "on" && tilts_as_fallback != "off") throw FlagError("--tilts-as-fallback must be on or off");
    options.recognize.tilts_as_fallback = tilts_as_fallback == "on";
    if (options.view_expiry_s <= 0) throw FlagError("--view-expiry must be > 0");
    if (!(options.recognize.sift.contrast_threshold > 0)) throw FlagError("--sift-contrast must be > 0");
    if (!(options.recognize.sift.equalise_clip >= 0)) throw FlagError("--sift-equalise must be >= 0");
    // (the learner's own ratio between views, for background pruning, stays the thesis' 0.6:
    // --ratio is recognition's)
    options.learn.sift = options.recognize.sift;
    service.start();
    learner_service::Handlers handlers(service, options);
    // The tick keeps the heartbeat's status current while the worker learns and answers LEARNED.
    const int code = service.run([&handlers] {
      handlers.poll();
      return 20;
    });
    handlers.finish_learning();  // a job under way is stored and answered, not cut off
    return code;
  });
}
