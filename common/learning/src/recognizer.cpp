#include "nudge/learning/recognizer.hpp"

#include <opencv2/calib3d.hpp>
#include <opencv2/features2d.hpp>

#include <algorithm>
#include <cmath>
#include <complex>
#include <map>
#include <mutex>
#include <set>
#include <stdexcept>

#include "database_index.hpp"
#include "seeded_rng.hpp"
#include "nudge/timing.hpp"

namespace nudge::learning {

MatcherKind matcher_from_name(const std::string& name) {
  if (name == "bf") return MatcherKind::BruteForce;
  if (name == "flann") return MatcherKind::Flann;
  if (name == "shared-flann") return MatcherKind::SharedFlann;
  throw std::invalid_argument("unknown matcher '" + name + "' (bf, flann or shared-flann)");
}

std::string matcher_name(MatcherKind kind) {
  switch (kind) {
    case MatcherKind::BruteForce: return "bf";
    case MatcherKind::Flann: return "flann";
    case MatcherKind::SharedFlann: return "shared-flann";
  }
  return "unknown";
}

// One object's descriptor set: every view's descriptors stacked (in one matcher index of its own
// unless the database's index holds them), each row knowing its view and its index within that view.
struct Recognizer::Entry {
  std::shared_ptr<const ObjectModel> model;
  std::vector<int> row_view, row_index;
  // The ratio test's group of each row: its view, and within the view the simulated tilt it was
  // found at (LearnParams::axis_tilts), so that a point's squeezed copy is not its own second
  // neighbour.
  std::vector<int> row_group;
  cv::Mat row_chroma;  // each row's chromaticity (chromaticities()), N x 2
  cv::Ptr<cv::DescriptorMatcher> matcher;  // null for a set of < 2 descriptors, and for SharedFlann
  // Views' features found at simulated tilts (at_simulated_tilt): the model without them, and for
  // each of its views the index of each of its features in the model's view. Null without any.
  std::shared_ptr<const ObjectModel> untilted;
  std::vector<std::vector<int>> untilted_index;
};

// SharedFlann: the index over every entry's descriptors, rebuilt after the entries change. Built
// lazily so that loading a database of n objects builds it once, not n times; the mutex lets
// concurrent const recognitions share that build.
struct Recognizer::SharedIndex {
  std::mutex mutex;
  bool stale = true;
  detail::DatabaseIndex index;
};

namespace {

// The descriptors as they are matched: RootSIFT (features.hpp) unless switched off.
cv::Mat matching_descriptors(const cv::Mat& sift, bool root) { return root ? root_sift(sift) : sift; }

cv::Ptr<cv::DescriptorMatcher> make_matcher(MatcherKind kind) {
  if (kind == MatcherKind::BruteForce) return cv::makePtr<cv::BFMatcher>(cv::NORM_L2);
  // Randomised k-d trees: 4 trees, 32 leaves checked (Lowe's and OpenCV's usual setting for SIFT).
  return cv::makePtr<cv::FlannBasedMatcher>(cv::makePtr<cv::flann::KDTreeIndexParams>(4),
                                           cv::makePtr<cv::flann::SearchParams>(32));
}

constexpr uint64_t kRansacSeed = 0x2008, kFlannSeed = 0x2009;  // any fixed values

// Neighbours looked at per query descriptor (see view_ratio_matches).
constexpr int kNeighbours = detail::kObjectNeighbours;

// Lowe's ratio test within one training view (row_group: the view, and the simulated tilt within it). Neighbouring views show the same surface point, so
// over the object's whole set (as the thesis matched) the second neighbour is often the same point
// one turn step on, failing a true match. Here d2 is the nearest neighbour in the same view as the
// nearest one; when none of the kNeighbours nearest is, the last of them stands in for it (the
// true d2 is no smaller, so the test is only stricter).
std::vector<cv::DMatch> view_ratio_matches(cv::DescriptorMatcher& matcher, const std::vector<int>& row_group,
                                           const cv::Mat& row_chroma, const cv::Mat& query, const cv::Mat& query_chroma,
                                           double ratio, float colour_tolerance) {
  std::vector<cv::DMatch> out;
  if (query.empty()) return out;
  const bool by_colour = colour_tolerance > 0 && query_chroma.rows == query.rows && !row_chroma.empty();
  std::vector<std::vector<cv::DMatch>> knn;
  matcher.knnMatch(query, knn, kNeighbours);
  for (const auto& neighbours : knn) {
    if (neighbours.size() < 2) continue;
    // A neighbour of another colour is no candidate, nearest or second (RecognizeParams::colour_tolerance).
    auto candidate = [&](const cv::DMatch& m) {
      return !by_colour || chromaticities_agree(query_chroma.ptr<float>(m.queryIdx), row_chroma.ptr<float>(m.trainIdx),
                                                colour_tolerance);
    };
    const auto nearest = std::find_if(neighbours.begin(), neighbours.end(), candidate);
    if (nearest == neighbours.end()) continue;
    float second = neighbours.back().distance;
    for (auto it = std::next(nearest); it != neighbours.end(); ++it) {
      if (candidate(*it) && row_group[it->trainIdx] == row_group[nearest->trainIdx]) {
        second = it->distance;
        break;
      }
    }
    if (nearest->distance < ratio * second) out.push_back(*nearest);
  }
  return out;
}

// One match per training point and per query point. SIFT gives a point several keypoints when it
// has several dominant orientations; their matches are one piece of evidence, not several, and
// would otherwise agree with each other in any geometric check.
std::vector<cv::DMatch> one_per_point(std::vector<cv::DMatch> matches, const Features& query, const Features& view) {
  std::sort(matches.begin(), matches.end(), [](const cv::DMatch& a, const cv::DMatch& b) { return a.distance < b.distance; });
  auto key = [](const cv::Point2f& p) { return std::make_pair(std::lround(p.x * 2), std::lround(p.y * 2)); };
  std::set<std::pair<long, long>> used_query, used_train;
  std::vector<cv::DMatch> out;
  for (const auto& m : matches) {
    const auto q = key(query.keypoints[m.queryIdx].pt), t = key(view.keypoints[m.trainIdx].pt);
    if (used_query.count(q) || used_train.count(t)) continue;
    used_query.insert(q);
    used_train.insert(t);
    out.push_back(m);
  }
  return out;
}

// A homography is tried only with this many matches, an affine map with this many: fewer fit them
// too easily.
constexpr int kHomographyMinMatches = 10;
constexpr int kAffineMinMatches = 6;
// An affine map's linear part: kept unless mirrored, or squashing one direction over this many
// times more than the other (a surface seen at up to ~80 degrees of tilt).
constexpr double kMaxAnisotropy = 6;

bool plausible_view_map(const cv::Mat& linear) {
  cv::Mat singular;
  cv::SVD::compute(linear, singular, cv::SVD::NO_UV);
  const double s_max = singular.at<double>(0), s_min = singular.at<double>(1);
  return cv::determinant(linear) > 0 && s_min > 1e-3 && s_max / s_min <= kMaxAnisotropy;
}

// The local linear part of `map` (a 2x3 affine map or a 3x3 homography, CV_64F) at `p`: how a
// small neighbourhood of p is turned, scaled and squeezed.
cv::Matx22d local_linear(const cv::Mat& map, const cv::Point2f& p) {
  const cv::Mat_<double> m(map);
  if (m.rows == 2) return {m(0, 0), m(0, 1), m(1, 0), m(1, 1)};
  const double w = m(2, 0) * p.x + m(2, 1) * p.y + m(2, 2);
  const double x = (m(0, 0) * p.x + m(0, 1) * p.y + m(0, 2)) / w, y = (m(1, 0) * p.x + m(1, 1) * p.y + m(1, 2)) / w;
  return cv::Matx22d(m(0, 0) - x * m(2, 0), m(0, 1) - x * m(2, 1), m(1, 0) - y * m(2, 0), m(1, 1) - y * m(2, 1)) * (1 / w);
}

// A training keypoint's SIFT orientation (radians) and size in its view's own coordinates. One found
// at a simulated tilt was found in the view squeezed by the tilt (its rows shrunk): unsqueezed, its
// direction is stretched along the rows and its size grows with the square root of the tilt.
struct ViewFrame {
  double angle = 0, size = 0;
};

ViewFrame view_frame(const cv::KeyPoint& train) {
  const double tilt = at_simulated_tilt(train) ? train.class_id / 100.0 : 1;
  const double a = train.angle * CV_PI / 180;
  return {std::atan2(tilt * std::sin(a), std::cos(a)), train.size * std::sqrt(tilt)};
}

// The agreement's tolerances as its rule compares them (radians, log of the scale factor): made
// once per check, not per match.
struct AgreementBounds {
  double max_turn, max_log_scale;
  explicit AgreementBounds(const KeypointAgreement& tolerance)
      : max_turn(tolerance.angle_deg * CV_PI / 180), max_log_scale(std::log(tolerance.scale_factor)) {}
};

// The agreement's rule, said once: a keypoint turned `turn_off` radians and scaled by exp(log_scale_off)
// away from what the mapping says at its place is within the tolerances.
bool within_agreement(double turn_off, double log_scale_off, const AgreementBounds& bounds) {
  return std::abs(std::remainder(turn_off, 2 * CV_PI)) <= bounds.max_turn && std::abs(log_scale_off) <= bounds.max_log_scale;
}

// Whether a match's two keypoints agree with the mapping found from the matches' positions: SIFT
// gives each keypoint an orientation and a scale, and a true match's query keypoint is its
// training keypoint turned and scaled as the mapping turns and scales that spot (Lowe 2004 votes on
// these for the same reason). A chance match whose position happens to fit a mapping rarely fits
// its orientation and scale as well, so a few such matches no longer make a recognition.
bool keypoint_agrees(const cv::Matx22d& linear_at_train, const cv::KeyPoint& train, const cv::KeyPoint& query,
                     const AgreementBounds& bounds) {
  const ViewFrame t = view_frame(train);
  const cv::Vec2d turned = linear_at_train * cv::Vec2d(std::cos(t.angle), std::sin(t.angle));
  const double off = query.angle * CV_PI / 180 - std::atan2(turned[1], turned[0]);
  const double scale = std::sqrt(std::abs(cv::determinant(linear_at_train)));
  if (!(scale > 0) || t.size <= 0 || query.size <= 0) return false;
  return within_agreement(off, std::log(query.size / (t.size * scale)), bounds);
}

// The inliers of `map` whose keypoints also agree with it (keypoint_agrees); all of them when the
// agreement is off.
std::vector<cv::DMatch> agreeing_inliers(const std::vector<cv::DMatch>& matches, const std::vector<uchar>& mask,
                                         const cv::Mat& map, const Features& query, const Features& view,
                                         const KeypointAgreement& agreement) {
  const AgreementBounds bounds(agreement);
  std::vector<cv::DMatch> out;
  for (size_t i = 0; i < matches.size(); ++i) {
    if (!mask[i]) continue;
    const cv::KeyPoint& t = view.keypoints[matches[i].trainIdx];
    if (agreement.on && !keypoint_agrees(local_linear(map, t.pt), t, query.keypoints[matches[i].queryIdx], bounds))
      continue;
    out.push_back(matches[i]);
  }
  return out;
}

// What one match says by itself about a similarity of the training view onto the query (Lowe
// 2004): the turn and the scale between its two keypoints' SIFT orientations and sizes.
struct MatchFrame {
  std::complex<double> from, to;
  double turn = 0, log_scale = 0;
};

MatchFrame frame_of(const cv::KeyPoint& train, const cv::KeyPoint& query) {
  const ViewFrame t = view_frame(train);
  MatchFrame f;
  f.from = {train.pt.x, train.pt.y};
  f.to = {query.pt.x, query.pt.y};
  f.turn = query.angle * CV_PI / 180 - t.angle;
  f.log_scale = std::log(std::max(query.size, 1e-3f) / std::max(t.size, 1e-3));
  return f;
}

// How many matches a similarity q = a * t + b (complex numbers: a turns and scales, b shifts)
// explains: within `px` of where it puts them and, with the agreement on, their keypoints turned and
// scaled as it turns and scales. Their indices go to `members` when given (RANSAC counts each
// hypothesis and collects only the best one's).
int similarity_support(const std::vector<MatchFrame>& frames, std::complex<double> a, std::complex<double> b,
                       double px, const KeypointAgreement& agreement, std::vector<int>* members = nullptr) {
  const double turn = std::arg(a), log_scale = std::log(std::abs(a));
  const AgreementBounds bounds(agreement);
  int count = 0;
  for (int i = 0; i < static_cast<int>(frames.size()); ++i) {
    const MatchFrame& f = frames[i];
    if (std::norm(a * f.from + b - f.to) > px * px) continue;
    if (agreement.on && !within_agreement(f.turn - turn, f.log_scale - log_scale, bounds)) continue;
    ++count;
    if (members) members->push_back(i);
  }
  return count;
}

// The least-squares similarity through the matches `chosen` (closed form, Umeyama's for 2-D).
std::pair<std::complex<double>, std::complex<double>> fitted_similarity(const std::vector<MatchFrame>& frames,
                                                                      const std::vector<int>& chosen) {
  std::complex<double> mean_from, mean_to;
  for (int i : chosen) {
    mean_from += frames[i].from;
    mean_to += frames[i].to;
  }
  mean_from /= static_cast<double>(chosen.size());
  mean_to /= static_cast<double>(chosen.size());
  std::complex<double> cross;
  double spread = 0;
  for (int i : chosen) {
    cross += (frames[i].to - mean_to) * std::conj(frames[i].from - mean_from);
    spread += std::norm(frames[i].from - mean_from);
  }
  const std::complex<double> a = spread > 0 ? cross / spread : std::complex<double>();
  return {a, mean_to - a * mean_from};
}

// The largest set of matches one similarity explains, by RANSAC on pairs of matches (every pair
// when there are few, else a fixed number drawn from a fixed seed), its consensus judged on place
// and keypoint agreement together: a mapping found from places alone may win on chance matches and
// leave too few agreeing ones, where another would have kept them all. Refitted to its consensus.
std::vector<cv::DMatch> similarity_inliers(const std::vector<cv::DMatch>& matches, const Features& query,
                                           const Features& view, const RecognizeParams& params) {
  std::vector<MatchFrame> frames;
  for (const auto& m : matches) frames.push_back(frame_of(view.keypoints[m.trainIdx], query.keypoints[m.queryIdx]));
  const int n = static_cast<int>(frames.size());
  constexpr int kMaxPairs = 2000;
  std::vector<std::pair<int, int>> pairs;
  if (n * (n - 1) / 2 <= kMaxPairs) {
    for (int i = 0; i < n; ++i)
      for (int j = i + 1; j < n; ++j) pairs.emplace_back(i, j);
  } else {
    cv::RNG rng(kRansacSeed);
    while (static_cast<int>(pairs.size()) < kMaxPairs) {
      const int i = rng.uniform(0, n), j = rng.uniform(0, n);
      if (i != j) pairs.emplace_back(i, j);
    }
  }
  int best_count = 0;
  std::complex<double> best_a, best_b;
  for (const auto& [i, j] : pairs) {
    const std::complex<double> span = frames[j].from - frames[i].from;
    if (std::abs(span) < 1) continue;  // one spot: no turn or scale to fix
    const std::complex<double> a = (frames[j].to - frames[i].to) / span;
    if (std::abs(a) < 1e-3) continue;
    const std::complex<double> b = frames[i].to - a * frames[i].from;
    const int count = similarity_support(frames, a, b, params.ransac_px, params.keypoint_agreement);
    if (count <= best_count) continue;
    best_count = count;
    best_a = a;
    best_b = b;
  }
  std::vector<int> best;
  if (best_count > 0) similarity_support(frames, best_a, best_b, params.ransac_px, params.keypoint_agreement, &best);
  if (best.size() >= 2) {
    const auto [a, b] = fitted_similarity(frames, best);
    if (std::abs(a) > 1e-3) {
      std::vector<int> refitted;
      similarity_support(frames, a, b, params.ransac_px, params.keypoint_agreement, &refitted);
      if (refitted.size() >= best.size()) best = std::move(refitted);
    }
  }
  std::vector<cv::DMatch> out;
  for (int i : best) out.push_back(matches[i]);
  return out;
}

// How many distinct places of the training view `matches` show: greedy clusters of their training
// keypoints, a keypoint joining the first cluster whose seed lies within `radius_px` of it.
int distinct_places(const std::vector<cv::DMatch>& matches, const Features& view, double radius_px) {
  if (radius_px <= 0) return static_cast<int>(matches.size());
  std::vector<cv::Point2f> seeds;
  for (const auto& m : matches) {
    const cv::Point2f p = view.keypoints[m.trainIdx].pt;
    const bool near_seed = std::any_of(seeds.begin(), seeds.end(), [&](const cv::Point2f& s) {
      const cv::Point2f d = p - s;
      return d.dot(d) < radius_px * radius_px;
    });
    if (!near_seed) seeds.push_back(p);
  }
  return static_cast<int>(seeds.size());
}

// The largest set of matches one mapping of the training view onto the query explains: a
// similarity (rotation, scale, shift: 2 matches fix it) or, with enough matches, a homography (4
// fix it); every match of the set also agrees with the mapping in its keypoints' orientation and
// scale (RecognizeParams::keypoint_agreement). The matches that fixed the mapping agree with it by
// construction, so a set counts only when `min_support` more matches agree; otherwise none are
// verified.
std::vector<cv::DMatch> geometric_inliers(const std::vector<cv::DMatch>& matches, const Features& query,
                                          const Features& view, const RecognizeParams& params) {
  const double ransac_px = params.ransac_px;
  const int min_support = params.min_support;
  if (matches.size() < 3) return {};
  const detail::SeededThreadRng seeded(kRansacSeed);  // the same matches, the same inliers
  std::vector<cv::Point2f> from, to;
  for (const auto& m : matches) {
    from.push_back(view.keypoints[m.trainIdx].pt);
    to.push_back(query.keypoints[m.queryIdx].pt);
  }
  std::vector<cv::DMatch> best;
  std::vector<uchar> mask;
  // A mapping fixed by `fixing` matches counts when `min_support` more agree, and its inliers lie at
  // as many distinct places as a similarity needs (the fewest any mapping needs).
  auto enough = [&](const std::vector<cv::DMatch>& inliers, int fixing) {
    return static_cast<int>(inliers.size()) >= fixing + min_support &&
           distinct_places(inliers, view, params.distinct_place_px) >= 2 + min_support;
  };
  auto similar = similarity_inliers(matches, query, view, params);
  if (enough(similar, 2)) best = std::move(similar);
  // Whether a homography is worth its RANSAC (2000 draws of four matches, ~10 ms on a view of
  // chance matches, most of a recognition's time): with the affine check on, only when an affine
  // map already puts enough matches in place. A label is a small patch of the view, where a true
  // homography is close to affine; chance matches rarely fit either.
  bool homography_worth_trying = static_cast<int>(matches.size()) >= kHomographyMinMatches;
  // A label seen at another tilt (a bottle lying down, seen from above) is foreshortened along one
  // direction: an affine map (3 matches fix it) explains it where a similarity cannot. Mirrored or
  // nearly collapsed maps are no view of a surface.
  if (params.affine_check && static_cast<int>(matches.size()) >= kAffineMinMatches) {
    const cv::Mat a = cv::estimateAffine2D(from, to, mask, cv::RANSAC, ransac_px, 2000, 0.995);
    homography_worth_trying = homography_worth_trying && !a.empty() && cv::countNonZero(mask) >= 4 + min_support;
    if (!a.empty() && plausible_view_map(a(cv::Rect(0, 0, 2, 2)))) {
      auto inliers = agreeing_inliers(matches, mask, a, query, view, params.keypoint_agreement);
      if (enough(inliers, 3) && inliers.size() > best.size()) best = std::move(inliers);
    }
  }
  if (homography_worth_trying) {
    const cv::Mat h = cv::findHomography(from, to, cv::RANSAC, ransac_px, mask, 2000, 0.995);
    // A mirrored or collapsed mapping is not a view of a surface.
    if (!h.empty() && cv::determinant(h(cv::Rect(0, 0, 2, 2))) > 1e-4) {
      auto inliers = agreeing_inliers(matches, mask, h, query, view, params.keypoint_agreement);
      if (enough(inliers, 4) && inliers.size() > best.size()) best = std::move(inliers);
    }
  }
  return best;
}

// `model` without the features found at simulated tilts, and per view the index of each feature kept
// in the model's own view; null when it has none.
std::shared_ptr<const ObjectModel> without_tilts(const ObjectModel& model, std::vector<std::vector<int>>* index) {
  bool any = false;
  for (const auto& view : model.views)
    any = any || std::any_of(view.features.keypoints.begin(), view.features.keypoints.end(), at_simulated_tilt);
  if (!any) return nullptr;
  auto out = std::make_shared<ObjectModel>();
  out->info = model.info;
  index->assign(model.views.size(), {});
  for (size_t v = 0; v < model.views.size(); ++v) {
    ModelView kept = model.views[v];  // box, angle and image shared; the features replaced below
    std::vector<bool> as_taken(kept.features.size());
    for (int k = 0; k < kept.features.size(); ++k) {
      as_taken[k] = !at_simulated_tilt(kept.features.keypoints[k]);
      if (as_taken[k]) (*index)[v].push_back(k);
    }
    kept.features = select_features(kept.features, as_taken);
    out->views.push_back(std::move(kept));
  }
  return out;
}

}  // namespace

Recognizer::Recognizer(const RecognizeParams& params)
    : params_(params),
      shared_(params.matcher == MatcherKind::SharedFlann ? std::make_unique<SharedIndex>() : nullptr) {
  // Fewer than two neighbours leave no second one for the ratio test: nothing would ever match.
  if (shared_ && params.shared_neighbours < 2)
    throw std::invalid_argument("RecognizeParams::shared_neighbours must be >= 2, not " +
                                std::to_string(params.shared_neighbours));
  if (shared_ && params.shared_checks < 1)
    throw std::invalid_argument("RecognizeParams::shared_checks must be >= 1, not " + std::to_string(params.shared_checks));
  // A tolerance that nothing passes (or that everything does, past half a turn) is a mistake.
  const KeypointAgreement& agreement = params.keypoint_agreement;
  if (agreement.on && !(agreement.angle_deg > 0 && agreement.angle_deg <= 180))
    throw std::invalid_argument("RecognizeParams::keypoint_agreement.angle_deg must be in (0, 180], not " +
                                std::to_string(agreement.angle_deg));
  if (!(params.colour_tolerance >= 0))
    throw std::invalid_argument("RecognizeParams::colour_tolerance must be >= 0, not " +
                                std::to_string(params.colour_tolerance));
  if (!(params.distinct_place_px >= 0))
    throw std::invalid_argument("RecognizeParams::distinct_place_px must be >= 0, not " +
                                std::to_string(params.distinct_place_px));
  if (agreement.on && !(agreement.scale_factor >= 1))
    throw std::invalid_argument("RecognizeParams::keypoint_agreement.scale_factor must be >= 1, not " +
                                std::to_string(agreement.scale_factor));
}
Recognizer::~Recognizer() = default;
Recognizer::Recognizer(Recognizer&&) noexcept = default;
Recognizer& Recognizer::operator=(Recognizer&&) noexcept = default;

void Recognizer::add(std::shared_ptr<const ObjectModel> model) {
  auto entry = std::make_unique<Entry>();
  cv::Mat all(0, 128, CV_32F);
  int next_group = 0;
  for (size_t v = 0; v < model->views.size(); ++v) {
    const Features& f = model->views[v].features;
    if (!f.descriptors.empty() && (f.descriptors.type() != CV_32F || f.descriptors.cols != 128))
      throw std::invalid_argument("object '" + model->info.name + "' view " + std::to_string(v) +
                                  ": descriptors are not SIFT's (CV_32F, 128 wide)");
    if (f.descriptors.rows != f.size())
      throw std::invalid_argument("object '" + model->info.name + "' view " + std::to_string(v) + ": " +
                                  std::to_string(f.size()) + " keypoints but " + std::to_string(f.descriptors.rows) +
                                  " descriptors");
    std::map<int, int> group_of_layer;  // class_id -> ratio-test group, within this view
    for (int k = 0; k < f.size(); ++k) {
      entry->row_view.push_back(static_cast<int>(v));
      entry->row_index.push_back(k);
      auto [it, fresh] = group_of_layer.emplace(f.keypoints[k].class_id, 0);
      if (fresh) it->second = next_group++;
      entry->row_group.push_back(it->second);
    }
    if (!f.colours.empty() && (f.colours.rows != f.size() || f.colours.cols != 3 || f.colours.type() != CV_32F))
      throw std::invalid_argument("object '" + model->info.name + "' view " + std::to_string(v) + ": " +
                                  std::to_string(f.size()) + " keypoints but " + std::to_string(f.colours.rows) +
                                  " colours of " + std::to_string(f.colours.cols) + " values");
    entry->row_chroma.push_back(chromaticities(f.colours, f.size()));
    if (!f.descriptors.empty() && !shared_) all.push_back(matching_descriptors(f.descriptors, params_.root_sift));
  }
  if (all.rows >= 2 && !shared_) {
    entry->matcher = make_matcher(params_.matcher);
    entry->matcher->add(all);
    // FLANN's trees built now, not on the first query, from seeded generators (seeded_rng.hpp).
    const detail::SeededThreadRng seeded(kFlannSeed);
    entry->matcher->train();
  }
  if (params_.tilts_as_fallback) entry->untilted = without_tilts(*model, &entry->untilted_index);
  entry->model = std::move(model);
  if (shared_) shared_->stale = true;
  const Entry& added = *entry;
  auto same = std::find_if(entries_.begin(), entries_.end(),
                           [&](const auto& e) { return e->model->info.name == added.model->info.name; });
  if (same != entries_.end())
    *same = std::move(entry);
  else
    entries_.push_back(std::move(entry));
  update_untilted(added);
}

void Recognizer::update_untilted(const Entry& added) {
  const bool any_tilted = std::any_of(entries_.begin(), entries_.end(), [](const auto& e) { return e->untilted != nullptr; });
  if (!any_tilted) {
    untilted_.reset();
    return;
  }
  if (untilted_) {  // it holds every other model already (add and remove keep it in step)
    untilted_->add(added.untilted ? added.untilted : added.model);
    return;
  }
  // The first model with tilted features: every model, in the same order.
  RecognizeParams plain = params_;
  plain.tilts_as_fallback = false;
  untilted_ = std::make_unique<Recognizer>(plain);
  for (const auto& e : entries_) untilted_->add(e->untilted ? e->untilted : e->model);
}

// The untilted pass's matches, trainIdx into the untilted view's features: into the model's own.
void Recognizer::remap_untilted(Recognition* result) const {
  for (ObjectScore& score : result->scores) {
    if (score.best_view < 0) continue;
    const auto entry = std::find_if(entries_.begin(), entries_.end(), [&](const auto& e) { return e->model->info.name == score.name; });
    if (entry == entries_.end() || !(*entry)->untilted) continue;
    const std::vector<int>& index = (*entry)->untilted_index[score.best_view];
    for (cv::DMatch& m : score.matches) m.trainIdx = index[m.trainIdx];
  }
}

bool Recognizer::remove(const std::string& name) {
  for (auto it = entries_.begin(); it != entries_.end(); ++it) {
    if ((*it)->model->info.name == name) {
      entries_.erase(it);
      if (shared_) shared_->stale = true;
      if (untilted_) untilted_->remove(name);
      if (std::none_of(entries_.begin(), entries_.end(), [](const auto& e) { return e->untilted != nullptr; })) untilted_.reset();
      return true;
    }
  }
  return false;
}

void Recognizer::build_index() const {
  if (untilted_) untilted_->build_index();
  if (!shared_) return;
  std::lock_guard<std::mutex> lock(shared_->mutex);
  if (!shared_->stale) return;
  std::vector<detail::IndexedObject> objects(entries_.size());
  for (size_t i = 0; i < entries_.size(); ++i) {
    for (const auto& view : entries_[i]->model->views)
      objects[i].view_descriptors.push_back(matching_descriptors(view.features.descriptors, params_.root_sift));
    objects[i].row_group = &entries_[i]->row_group;
    objects[i].row_chroma = &entries_[i]->row_chroma;
  }
  shared_->index.build(objects);
  shared_->stale = false;
}

// Per entry, the query descriptors passing its ratio test, trainIdx the row in the entry's stack.
std::vector<std::vector<cv::DMatch>> Recognizer::ratio_matches_per_object(const cv::Mat& query,
                                                                         const cv::Mat& query_chroma) const {
  const auto tolerance = static_cast<float>(params_.colour_tolerance);
  if (shared_) {
    build_index();
    detail::IndexSearch search;
    search.neighbours = params_.shared_neighbours;
    search.checks = params_.shared_checks;
    search.ratio = params_.ratio;
    search.colour_tolerance = tolerance;
    return shared_->index.ratio_matches(query, query_chroma, search);
  }
  std::vector<std::vector<cv::DMatch>> out;
  for (const auto& entry : entries_) {
    out.push_back(entry->matcher ? view_ratio_matches(*entry->matcher, entry->row_group, entry->row_chroma, query,
                                                      query_chroma, params_.ratio, tolerance)
                                 : std::vector<cv::DMatch>{});
  }
  return out;
}

int Recognizer::size() const { return static_cast<int>(entries_.size()); }
const ObjectModel& Recognizer::model(int index) const { return *entries_.at(index)->model; }

const ObjectModel* Recognizer::find(const std::string& name) const {
  for (const auto& e : entries_)
    if (e->model->info.name == name) return e->model.get();
  return nullptr;
}

Recognition Recognizer::recognize(const cv::Mat& image, const cv::Rect& roi) const {
  Stopwatch watch;
  if (image.empty()) throw std::invalid_argument("recognize: empty image");
  const cv::Rect area = roi.empty() ? cv::Rect(cv::Point(0, 0), image.size()) : roi & cv::Rect(cv::Point(0, 0), image.size());
  if (area.empty()) throw std::invalid_argument("recognize: the region lies outside the image");
  // With equalisation: over the whole image, as the learner's views are, then cut to the region.
  // Without: only the region is turned grey.
  SiftParams as_is = params_.sift;
  as_is.equalise_clip = 0;
  const cv::Mat source = params_.sift.equalise_clip > 0 ? sift_grey(image, params_.sift) : image;
  Features query = detect_features(source(area), as_is);
  for (auto& k : query.keypoints) k.pt += cv::Point2f(static_cast<float>(area.x), static_cast<float>(area.y));
  // SIFT's source was grey when equalised: the colours then come from the image as given.
  if (query.colours.empty()) query.colours = keypoint_colours(image, query.keypoints);
  Recognition result = recognize(query);
  result.elapsed_ms = watch.elapsed_ms();
  return result;
}

Recognition Recognizer::recognize(const Features& query) const {
  Stopwatch watch;
  if (untilted_) {
    Recognition untilted = untilted_->recognize(query);
    if (untilted.recognised()) {
      remap_untilted(&untilted);
      untilted.elapsed_ms = watch.elapsed_ms();
      return untilted;
    }
  }
  Recognition result = recognize_all_features(query);
  result.elapsed_ms = watch.elapsed_ms();
  return result;
}

Recognition Recognizer::recognize_all_features(const Features& query) const {
  Stopwatch watch;
  Recognition result;
  result.query = query;
  const cv::Mat query_chroma = params_.colour_tolerance > 0 ? chromaticities(query.colours, query.size()) : cv::Mat();
  const std::vector<std::vector<cv::DMatch>> object_matches =
      ratio_matches_per_object(matching_descriptors(query.descriptors, params_.root_sift), query_chroma);
  for (size_t e = 0; e < entries_.size(); ++e) {
    const auto& entry = entries_[e];
    ObjectScore score;
    score.name = entry->model->info.name;
    // Ratio-test matches, grouped by training view, trainIdx into that view's own features.
    std::map<int, std::vector<cv::DMatch>> by_view;
    for (cv::DMatch m : object_matches[e]) {
      const int view = entry->row_view[m.trainIdx];
      m.trainIdx = entry->row_index[m.trainIdx];
      m.imgIdx = view;
      by_view[view].push_back(m);
    }
    std::vector<std::pair<int, std::vector<cv::DMatch>>> views;
    for (auto& [view, view_matches] : by_view)
      views.emplace_back(view, one_per_point(view_matches, query, entry->model->views[view].features));
    // Most matches first: a view with no more matches than the best verified count cannot beat it,
    // so its geometric check is skipped.
    std::stable_sort(views.begin(), views.end(),
                     [](const auto& x, const auto& y) { return x.second.size() > y.second.size(); });
    for (const auto& [view, matches] : views) {
      score.ratio_matches += static_cast<int>(matches.size());
      if (static_cast<int>(matches.size()) <= score.verified_matches) continue;
      const Features& features = entry->model->views[view].features;
      const std::vector<cv::DMatch> kept =
          params_.geometric_check ? geometric_inliers(matches, query, features, params_) : matches;
      if (static_cast<int>(kept.size()) > score.verified_matches) {
        score.verified_matches = static_cast<int>(kept.size());
        score.best_view = view;
        score.matches = kept;
      }
    }
    result.scores.push_back(std::move(score));
  }
  int best = -1;
  for (int i = 0; i < static_cast<int>(result.scores.size()); ++i)
    if (best < 0 || result.scores[i].verified_matches > result.scores[best].verified_matches) best = i;
  if (entries_.empty()) {
    result.reason = "empty database";
  } else if (query.empty()) {
    result.reason = "no SIFT features in the image";
  } else if (result.scores[best].verified_matches < params_.min_matches) {
    result.reason = "no object matched " + std::to_string(params_.min_matches) + " or more features";
  } else {
    result.best = best;
  }
  result.elapsed_ms = watch.elapsed_ms();
  return result;
}

}  // namespace nudge::learning
