#pragma once
// Recognition against learned object models (thesis sec. 7.3.4): Lowe's ratio test against each
// object's training views in turn, a geometric check per training view so that a match is a match,
// and the thesis' rule that the best object needs three or more matches.
#include <opencv2/core.hpp>

#include <memory>
#include <string>
#include <vector>

#include "nudge/learning/model.hpp"

namespace nudge::learning {

// How descriptors are matched: per object exhaustively (BruteForce) or by FLANN's randomised k-d
// trees (Flann), one index per object searched in turn; or (SharedFlann) one FLANN index over the
// whole database, searched once per query, each object's ratio test on its own neighbours among the
// results. bench/learning_bench.cpp measures them against database size (docs/benchmarks.md).
enum class MatcherKind { BruteForce, Flann, SharedFlann };
// "bf" | "flann" | "shared-flann"; throws std::invalid_argument naming the unknown name.
MatcherKind matcher_from_name(const std::string& name);
std::string matcher_name(MatcherKind kind);

// The geometric check's second test: a verified match's query keypoint must be its training
// keypoint turned and scaled as the mapping turns and scales that spot (recognizer.cpp,
// keypoint_agrees), within these tolerances.
struct KeypointAgreement {
  bool on = true;
  double angle_deg = 30;     // SIFT's orientation off the mapping's turn by at most this
  double scale_factor = 2;   // SIFT's size off the mapping's scale by at most this factor either way
};

struct RecognizeParams {
  // d1 < ratio * d2 (thesis: N = 0.6, Lowe 2004: 0.8). The thesis' ratio passes only 2-5 matches on
  // a label seen lying down or partly hidden; Lowe's passes many more true and chance matches, and
  // the geometric check's keypoint agreement refuses the chance ones. It took one bottle's outline
  // for another's only through the supervisor's standing view, now off by default
  // (docs/learning.md, "A looser ratio test").
  double ratio = 0.8;
  int min_matches = 3;          // the best object needs this many verified matches (thesis: 3)
  bool geometric_check = true;  // similarity, affine map or homography per training view (RANSAC)
  int min_support = 2;          // matches agreeing with a mapping beyond those that fixed it
  bool affine_check = true;     // also an affine map (foreshortening), from 6 matches
  bool root_sift = true;        // match RootSIFT (Hellinger distance) rather than raw SIFT descriptors
  double ransac_px = 6.0;       // reprojection error an inlier may have, pixels
  // Matches whose training keypoints lie within this many pixels of one another show one place of
  // the label (SIFT finds several keypoints at the scales and corners of one small mark): a
  // mapping counts only when its inliers lie at 2 + min_support distinct places or more (what a
  // similarity needs in matches). A cluster of keypoints on one shared mark (a letter of the same
  // font, a line's corner) otherwise verifies any object carrying that mark. 0: every match is a
  // place of its own.
  double distinct_place_px = 10.0;
  KeypointAgreement keypoint_agreement;  // and the keypoints' orientation and scale must fit it too
  // The ratio test by colour as well: a training keypoint whose mean colour's chromaticity lies
  // further than this from the query keypoint's (chromaticities_agree) is neither its match nor the
  // second neighbour that fails it. Like shapes in different colours (a label's red and blue drops)
  // then stop failing each other's ratio test. Keypoints of unknown colour (a grey image, a
  // database from before colours were kept) or too dark to tell take part as before. 0: off.
  double colour_tolerance = 0;
  MatcherKind matcher = MatcherKind::SharedFlann;  // fastest at every database size measured
  // SharedFlann only: neighbours fetched per query descriptor over the whole database (enough that
  // an object's two nearest are usually among them) and k-d tree leaves checked to find them.
  int shared_neighbours = 16;
  int shared_checks = 64;
  SiftParams sift;              // of the query image (recognize(image, roi)); as the learner's
  // Features the learner found at simulated tilts (LearnParams::axis_tilts) are matched only when
  // the views as taken recognise nothing: a second pass over every feature. A query the views as
  // taken recognise is then recognised exactly as without the tilts; their squeezed copies
  // neither crowd its neighbours nor its ratio test. false: one pass over every feature.
  bool tilts_as_fallback = true;
};

// How one object scored against the query.
struct ObjectScore {
  std::string name;
  int ratio_matches = 0;            // passed the ratio test, summed over the views
  int verified_matches = 0;         // geometric inliers in the best view (its ratio matches when unchecked)
  int best_view = -1;
  std::vector<cv::DMatch> matches;  // verified: queryIdx into the query, trainIdx into best_view's features
};

struct Recognition {
  int best = -1;                    // index into scores; -1: nothing recognised
  std::string reason;               // why nothing was recognised
  std::vector<ObjectScore> scores;  // one per object, in the recognizer's order
  Features query;                   // the query image's features (in full-image coordinates)
  double elapsed_ms = 0;

  bool recognised() const { return best >= 0; }
  const ObjectScore* best_score() const { return best >= 0 ? &scores[best] : nullptr; }
};

class Recognizer {
 public:
  // Throws std::invalid_argument naming the parameter when a SharedFlann setting or a keypoint
  // agreement tolerance is out of range.
  explicit Recognizer(const RecognizeParams& params = {});
  ~Recognizer();
  Recognizer(Recognizer&&) noexcept;
  Recognizer& operator=(Recognizer&&) noexcept;

  // Adds a model, or replaces the one of the same name; throws std::invalid_argument naming the
  // object and view when a view's descriptors are not SIFT's or do not match its keypoints. Per-object matchers build the object's
  // index now; SharedFlann marks the database's index stale (build_index or the next recognize
  // rebuilds it), so that loading many objects builds it once.
  void add(std::shared_ptr<const ObjectModel> model);
  bool remove(const std::string& name);
  // Builds the shared index now if it is stale, so that the next recognition does not pay for it;
  // nothing to do for per-object matchers.
  void build_index() const;
  int size() const;
  const ObjectModel& model(int index) const;
  const ObjectModel* find(const std::string& name) const;
  const RecognizeParams& params() const { return params_; }

  // Which object `image` shows, looking inside `roi` only (empty: the whole image). Throws
  // std::invalid_argument for an empty or non-8-bit image.
  Recognition recognize(const cv::Mat& image, const cv::Rect& roi = {}) const;
  // The same on features already detected.
  Recognition recognize(const Features& query) const;

 private:
  struct Entry;
  struct SharedIndex;
  std::vector<std::vector<cv::DMatch>> ratio_matches_per_object(const cv::Mat& query_descriptors,
                                                                 const cv::Mat& query_chroma) const;
  Recognition recognize_all_features(const Features& query) const;
  // tilts_as_fallback: the models without their tilted features, kept while any model has them.
  void update_untilted(const Entry& added);
  void remap_untilted(Recognition* result) const;
  RecognizeParams params_;
  std::vector<std::unique_ptr<Entry>> entries_;
  std::unique_ptr<SharedIndex> shared_;  // SharedFlann only
  std::unique_ptr<Recognizer> untilted_;
};

// Thesis fig. 7.10: the query image above the best training view, the verified matches as red
// lines, the label in green. `training_image` is that view's picture (BGR or grey).
cv::Mat draw_match_picture(const cv::Mat& query_image, const cv::Mat& training_image, const Features& training,
                           const Recognition& result);

}  // namespace nudge::learning
