// Dynamic-programming score table (thesis Algorithm 3) and backtracking (Algorithm 4).
//
// Rewards, not costs: a cell's score is the best continuity reachable there. Each row takes a
// vertical step from the three cells above (8-connected), then a left-to-right and a right-to-left
// horizontal pass. The thesis keeps one back pointer per cell plus a copy for horizontal runs, because
// the two horizontal passes can otherwise form cycles inside a row. Here each pass keeps its own
// "came from my neighbour" flag and each cell remembers which of the three steps won: backtracking
// follows one pass's flags to the start of its run, so it cannot cycle.
#include <algorithm>
#include <limits>
#include <stdexcept>

#include "nudge/segmentation/segment.hpp"

namespace nudge::segmentation {

namespace {

enum class Step : uint8_t { Vertical, LeftToRight, RightToLeft };

struct ScoreTable {
  cv::Mat score;           // CV_64F, >= 0
  cv::Mat from_above;      // CV_32S: column in the row above, -1 = the contour starts here
  cv::Mat from_left;       // CV_8U: the left-to-right run at this cell came from column - 1
  cv::Mat from_right;      // CV_8U: the right-to-left run at this cell came from column + 1
  cv::Mat step;            // CV_8U: which Step produced the cell's score
};

// One horizontal pass over a row (Alg. 3 step 2, or step 3 when `leftwards`).
void horizontal_pass(const float* sept, const std::vector<double>& vertical, const SegmentParams& p,
                     bool leftwards, std::vector<double>* run, uint8_t* came_from_neighbour) {
  const int columns = static_cast<int>(vertical.size());
  double previous = -std::numeric_limits<double>::infinity();
  for (int k = 0; k < columns; ++k) {
    const int c = leftwards ? columns - 1 - k : k;
    const double reward = sept[c] >= 0 ? sept[c] * p.reward_horizontal : p.penalty_horizontal;
    const double sideways = previous + reward;
    if (vertical[c] >= sideways) {
      previous = vertical[c];
      came_from_neighbour[c] = 0;
    } else {
      previous = sideways;
      came_from_neighbour[c] = 1;
    }
    (*run)[c] = previous;
  }
}

// Alg. 3 step 1: vertical continuity from the three cells above. A contour may start anywhere
// (score max(0, cost)), but only a positive cell above is a predecessor: backtracking stops where the
// score reaches 0. `above` is null for the first row.
void vertical_step(const float* sept, const double* above, const SegmentParams& p, std::vector<double>* vertical,
                   int* from_above) {
  const int columns = static_cast<int>(vertical->size());
  for (int c = 0; c < columns; ++c) {
    const double reward = sept[c] >= 0 ? sept[c] * p.reward_vertical : p.penalty_vertical;
    double best = std::max(0.0, reward);
    // Straight down first, so that ties (e.g. across a gap) keep the contour straight.
    for (const int k : {c, c - 1, c + 1}) {
      if (!above || k < 0 || k >= columns) continue;
      if (above[k] > 0 && above[k] + reward > best) {
        best = above[k] + reward;
        from_above[c] = k;
      }
    }
    (*vertical)[c] = best;
  }
}

ScoreTable score_table(const cv::Mat& sept, const SegmentParams& p) {
  const int rows = sept.rows, columns = sept.cols;
  ScoreTable t;
  t.score = cv::Mat::zeros(rows, columns, CV_64F);
  t.from_above = cv::Mat(rows, columns, CV_32S, cv::Scalar(-1));
  t.from_left = cv::Mat::zeros(rows, columns, CV_8U);
  t.from_right = cv::Mat::zeros(rows, columns, CV_8U);
  t.step = cv::Mat::zeros(rows, columns, CV_8U);
  std::vector<double> vertical(columns), rightwards(columns), leftwards(columns);

  for (int r = 0; r < rows; ++r) {
    const float* cells = sept.ptr<float>(r);
    const double* above = r > 0 ? t.score.ptr<double>(r - 1) : nullptr;
    vertical_step(cells, above, p, &vertical, t.from_above.ptr<int>(r));
    // Steps 2 and 3: horizontal continuity in both directions; the cell keeps the best of the three.
    horizontal_pass(cells, vertical, p, false, &rightwards, t.from_left.ptr<uint8_t>(r));
    horizontal_pass(cells, vertical, p, true, &leftwards, t.from_right.ptr<uint8_t>(r));
    double* score = t.score.ptr<double>(r);
    uint8_t* step = t.step.ptr<uint8_t>(r);
    for (int c = 0; c < columns; ++c) {
      score[c] = vertical[c];
      step[c] = static_cast<uint8_t>(Step::Vertical);
      if (rightwards[c] > score[c]) {
        score[c] = rightwards[c];
        step[c] = static_cast<uint8_t>(Step::LeftToRight);
      }
      if (leftwards[c] > score[c]) {
        score[c] = leftwards[c];
        step[c] = static_cast<uint8_t>(Step::RightToLeft);
      }
    }
  }
  return t;
}

}  // namespace

std::vector<Cell> Segmenter::best_path(const cv::Mat& sept_weights, double* best_score) const {
  if (best_score) *best_score = 0;
  if (sept_weights.empty()) return {};
  if (sept_weights.type() != CV_32FC1) throw std::invalid_argument("segmentation: SEPT weights must be CV_32F");
  const ScoreTable t = score_table(sept_weights, params_);

  double max_score = 0;
  cv::Point at;
  cv::minMaxLoc(t.score, nullptr, &max_score, nullptr, &at);
  if (max_score <= 0) return {};
  if (best_score) *best_score = max_score;

  // Algorithm 4: walk back from the best cell until the contour's start.
  std::vector<Cell> path;
  int r = at.y, c = at.x;
  auto step = static_cast<Step>(t.step.at<uint8_t>(r, c));
  while (true) {
    path.push_back({r, c});
    if (step == Step::LeftToRight && t.from_left.at<uint8_t>(r, c)) {
      --c;
      continue;
    }
    if (step == Step::RightToLeft && t.from_right.at<uint8_t>(r, c)) {
      ++c;
      continue;
    }
    const int k = t.from_above.at<int>(r, c);
    if (k < 0) break;
    --r;
    c = k;
    step = static_cast<Step>(t.step.at<uint8_t>(r, c));
  }
  std::reverse(path.begin(), path.end());
  return path;
}

}  // namespace nudge::segmentation
