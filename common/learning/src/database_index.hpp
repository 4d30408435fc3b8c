#pragma once
// One FLANN index over every object's descriptors (private to nudge_learning): a query is searched
// once for the whole database instead of once per object, and each object's ratio test is done on
// its own neighbours among the results (issue 11; docs/learning.md, "Recognition").
#include <opencv2/core.hpp>
#include <opencv2/flann.hpp>

#include <memory>
#include <vector>

namespace nudge::learning::detail {

// Neighbours an object's ratio test looks at (see view_ratio_test): the same for per-object and
// shared indexes, so both decide alike.
constexpr int kObjectNeighbours = 4;

// One object as the index sees it: its views' descriptors stacked, and the ratio-test group of each row.
struct IndexedObject {
  std::vector<cv::Mat> view_descriptors;  // CV_32F, 128 wide; empty views allowed
  // Each row's ratio-test group: its view, told apart by the simulated tilt it was found at (the
  // Recognizer's row_group).
  const std::vector<int>* row_group = nullptr;
  // Each row's chromaticity (chromaticities(), N x 2); null or empty: every colour unknown.
  const cv::Mat* row_chroma = nullptr;
};

struct IndexSearch {
  int neighbours = 16;  // fetched per query descriptor over the whole database
  int checks = 64;      // k-d tree leaves visited
  double ratio = 0.6;
  // A neighbour whose colour disagrees with the query descriptor's by more than this
  // (chromaticities_agree) is not a candidate at all, nearest or second; 0: colours ignored.
  float colour_tolerance = 0;
};

class DatabaseIndex {
 public:
  // Rebuilds from scratch (cheap next to learning an object: docs/benchmarks.md). An object with
  // fewer than two descriptors has no second neighbour to compare with: it is left out.
  void build(const std::vector<IndexedObject>& objects);
  int rows() const { return descriptors_.rows; }

  // Per object (in build order), the query rows passing its ratio test: queryIdx into the query,
  // trainIdx the row in that object's stack, distance the L2 distance.
  // `query_chroma`: the query rows' chromaticities (N x 2), used when search.colour_tolerance > 0.
  std::vector<std::vector<cv::DMatch>> ratio_matches(const cv::Mat& query, const cv::Mat& query_chroma,
                                                     const IndexSearch& search) const;

 private:
  cv::Mat descriptors_;                   // the index points into it: kept alive with it
  std::vector<int> row_object_, row_local_, row_group_;
  cv::Mat row_chroma_;                    // total x 2, -1 where unknown
  std::vector<int> object_rows_;          // rows per object (0 for one left out)
  std::unique_ptr<cv::flann::Index> index_;
};

}  // namespace nudge::learning::detail
