#include "database_index.hpp"

#include "seeded_rng.hpp"
#include "nudge/learning/features.hpp"

#include <algorithm>
#include <cmath>

namespace nudge::learning::detail {

constexpr unsigned kIndexSeed = 20080101;  // any fixed value: the index's trees, reproducibly

void DatabaseIndex::build(const std::vector<IndexedObject>& objects) {
  int total = 0;
  object_rows_.assign(objects.size(), 0);
  for (size_t o = 0; o < objects.size(); ++o) {
    int rows = 0;
    for (const cv::Mat& d : objects[o].view_descriptors) rows += d.rows;
    if (rows >= 2) object_rows_[o] = rows;
    total += object_rows_[o];
  }
  descriptors_.create(total, 128, CV_32F);
  row_object_.resize(total);
  row_local_.resize(total);
  row_group_.resize(total);
  row_chroma_.create(total, 2, CV_32F);
  row_chroma_.setTo(-1);
  int row = 0;
  for (size_t o = 0; o < objects.size(); ++o) {
    if (object_rows_[o] == 0) continue;
    const cv::Mat* chroma = objects[o].row_chroma;
    if (chroma && !chroma->empty() && chroma->rows == object_rows_[o])
      chroma->copyTo(row_chroma_.rowRange(row, row + object_rows_[o]));
    int local = 0;
    for (const cv::Mat& d : objects[o].view_descriptors) {
      if (d.empty()) continue;
      d.copyTo(descriptors_.rowRange(row, row + d.rows));
      for (int k = 0; k < d.rows; ++k, ++row, ++local) {
        row_object_[row] = static_cast<int>(o);
        row_local_[row] = local;
        row_group_[row] = (*objects[o].row_group)[local];
      }
    }
  }
  index_.reset();
  // Randomised k-d trees, as the per-object FLANN matcher uses (Lowe's usual setting for SIFT).
  // FLANN draws the trees' split dimensions from cv::theRNG() and shuffles with std::rand():
  // seeded here, the same database gives the same index, so a query's approximate neighbours (and
  // a close call between two objects) do not depend on what the process did before.
  if (total >= 2) {
    const SeededThreadRng seeded(kIndexSeed);
    index_ = std::make_unique<cv::flann::Index>(descriptors_, cv::flann::KDTreeIndexParams(4));
  }
}

namespace {

// One object's neighbours among a query descriptor's results, in order of distance, up to
// kObjectNeighbours: the nearest, the nearest in the nearest's view after it, the last seen.
struct ObjectNeighbours {
  int object = -1, count = 0;
  int nearest_row = -1;
  float nearest = 0, same_view = -1, last = 0;
};

}  // namespace

// Per object, the test of view_ratio_test (recognizer.cpp) on its own neighbours: d2 is the nearest
// in the nearest's view among the object's kObjectNeighbours nearest, else the last of those. When
// the results hold fewer of the object's neighbours than that and none in the view, the missing
// ones lie beyond the farthest result, so its distance stands in for d2: never more than the true
// d2, so the test is only stricter. Other objects' neighbours never enter an object's test: a
// feature two objects share passes for both.
std::vector<std::vector<cv::DMatch>> DatabaseIndex::ratio_matches(const cv::Mat& query, const cv::Mat& query_chroma,
                                                                   const IndexSearch& search) const {
  std::vector<std::vector<cv::DMatch>> out(object_rows_.size());
  if (!index_ || query.empty()) return out;
  const int k = std::min(search.neighbours, rows());
  cv::Mat indices, squared;  // FLANN's L2 gives squared distances
  index_->knnSearch(query, indices, squared, k, cv::flann::SearchParams(search.checks));
  const bool complete = k == rows();  // every row is among the results: nothing is missing
  const bool by_colour = search.colour_tolerance > 0 && query_chroma.rows == query.rows;
  std::vector<ObjectNeighbours> seen;
  for (int q = 0; q < query.rows; ++q) {
    const int* idx = indices.ptr<int>(q);
    const float* d2 = squared.ptr<float>(q);
    seen.clear();
    float farthest = 0;
    for (int j = 0; j < k; ++j) {
      if (idx[j] < 0) break;
      const float d = std::sqrt(std::max(0.f, d2[j]));
      farthest = d;
      const int row = idx[j], object = row_object_[row];
      // A neighbour of another colour is no candidate; the farthest result still bounds what lies beyond.
      if (by_colour && !chromaticities_agree(query_chroma.ptr<float>(q), row_chroma_.ptr<float>(row), search.colour_tolerance))
        continue;
      auto it = std::find_if(seen.begin(), seen.end(), [&](const ObjectNeighbours& n) { return n.object == object; });
      if (it == seen.end()) {
        seen.push_back({object, 1, row, d, -1, d});
        continue;
      }
      if (it->count >= kObjectNeighbours) continue;
      ++it->count;
      it->last = d;
      if (it->same_view < 0 && row_group_[row] == row_group_[it->nearest_row]) it->same_view = d;
    }
    for (const ObjectNeighbours& n : seen) {
      float second;
      if (n.same_view >= 0) {
        second = n.same_view;
      } else if (n.count >= kObjectNeighbours || complete) {
        if (n.count < 2) continue;  // (complete: the object has one row; it is left out anyway)
        second = n.last;
      } else {
        second = farthest;
      }
      if (n.nearest < search.ratio * second)
        out[n.object].emplace_back(q, row_local_[n.nearest_row], n.nearest);
    }
  }
  return out;
}

}  // namespace nudge::learning::detail
