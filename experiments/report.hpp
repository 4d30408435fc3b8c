#pragma once
// Helpers for experiment programs: result files (docs/results/NAME.{json,md}) written atomically,
// simple statistics, and line plots drawn with OpenCV (no plotting dependency).
#include <opencv2/core.hpp>

#include <string>
#include <vector>

#include "nudge/timing.hpp"

namespace nudge::experiments {

// Directory results go to: $NUDGE_RESULTS_DIR or <source>/docs/results.
std::string results_dir();
// Writes text to results_dir()/name atomically and says so on stderr.
void write_result(const std::string& name, const std::string& text);

double median(std::vector<double> v);
using nudge::thread_cpu_ms;  // the calling thread's CPU time, ms (nudge/timing.hpp)
double mean(const std::vector<double>& v);

struct LinearFit {
  double slope = 0, intercept = 0, r2 = 0;
};
LinearFit fit_line(const std::vector<double>& x, const std::vector<double>& y);

struct Series {
  std::string label;
  std::vector<double> x, y;
  cv::Scalar colour{200, 80, 0};
  bool points = true;  // markers
  bool lines = true;   // join consecutive points
};
// A line plot with axes, ticks and a legend.
cv::Mat plot(const std::vector<Series>& series, const std::string& title, const std::string& x_label,
             const std::string& y_label, cv::Size size = {720, 480});
void write_png(const std::string& name, const cv::Mat& image);

// Images of one size and type in a grid, `columns` a row; a short last row is padded with white.
cv::Mat tile(std::vector<cv::Mat> images, int columns);

// "Machine: <cpu model>, <cores> cores" for result files.
std::string machine_description();
std::string today();

}  // namespace nudge::experiments
