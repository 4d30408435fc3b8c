#include "report.hpp"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <iostream>
#include <numeric>
#include <thread>

#include "nudge/atomic_file.hpp"

namespace nudge::experiments {

std::string results_dir() {
  if (const char* dir = std::getenv("NUDGE_RESULTS_DIR")) return dir;
  return std::string(NUDGE_SOURCE_DIR) + "/docs/results";
}

void write_result(const std::string& name, const std::string& text) {
  const std::string path = results_dir() + "/" + name;
  write_file_atomically(path, text);
  std::cerr << "wrote " << path << "\n";
}

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

double mean(const std::vector<double>& v) {
  return v.empty() ? 0 : std::accumulate(v.begin(), v.end(), 0.0) / v.size();
}

LinearFit fit_line(const std::vector<double>& x, const std::vector<double>& y) {
  LinearFit f;
  const double mx = mean(x), my = mean(y);
  double sxy = 0, sxx = 0, syy = 0;
  for (size_t i = 0; i < x.size(); ++i) {
    sxy += (x[i] - mx) * (y[i] - my);
    sxx += (x[i] - mx) * (x[i] - mx);
    syy += (y[i] - my) * (y[i] - my);
  }
  if (sxx <= 0) return f;
  f.slope = sxy / sxx;
  f.intercept = my - f.slope * mx;
  f.r2 = syy > 0 ? (sxy * sxy) / (sxx * syy) : 1.0;
  return f;
}

namespace {
double nice_step(double range) {
  const double raw = range / 6;
  const double mag = std::pow(10, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0, 10.0})
    if (raw <= m * mag) return m * mag;
  return 10 * mag;
}
std::string tick_text(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, std::fabs(v) >= 100 || v == std::floor(v) ? "%.0f" : "%.2g", v);
  return buf;
}
}  // namespace

cv::Mat plot(const std::vector<Series>& series, const std::string& title, const std::string& x_label,
             const std::string& y_label, cv::Size size) {
  cv::Mat img(size, CV_8UC3, cv::Scalar(255, 255, 255));
  double x0 = 1e300, x1 = -1e300, y0 = 0, y1 = -1e300;
  for (const auto& s : series) {
    for (double v : s.x) { x0 = std::min(x0, v); x1 = std::max(x1, v); }
    for (double v : s.y) { y0 = std::min(y0, v); y1 = std::max(y1, v); }
  }
  if (x1 <= x0) x1 = x0 + 1;
  if (y1 <= y0) y1 = y0 + 1;
  y1 += 0.05 * (y1 - y0);
  const cv::Rect area(70, 40, size.width - 100, size.height - 100);
  auto px = [&](double x, double y) {
    return cv::Point(static_cast<int>(area.x + (x - x0) / (x1 - x0) * area.width),
                     static_cast<int>(area.y + area.height - (y - y0) / (y1 - y0) * area.height));
  };
  const cv::Scalar black(0, 0, 0), grey(220, 220, 220);
  for (double t = std::ceil(x0 / nice_step(x1 - x0)) * nice_step(x1 - x0); t <= x1 + 1e-9; t += nice_step(x1 - x0)) {
    cv::line(img, px(t, y0), px(t, y1), grey);
    cv::putText(img, tick_text(t), px(t, y0) + cv::Point(-10, 18), cv::FONT_HERSHEY_SIMPLEX, 0.4, black);
  }
  for (double t = std::ceil(y0 / nice_step(y1 - y0)) * nice_step(y1 - y0); t <= y1 + 1e-9; t += nice_step(y1 - y0)) {
    cv::line(img, px(x0, t), px(x1, t), grey);
    cv::putText(img, tick_text(t), px(x0, t) + cv::Point(-50, 4), cv::FONT_HERSHEY_SIMPLEX, 0.4, black);
  }
  cv::rectangle(img, area, black);
  cv::putText(img, title, {area.x, 25}, cv::FONT_HERSHEY_SIMPLEX, 0.55, black, 1, cv::LINE_AA);
  cv::putText(img, x_label, {area.x + area.width / 2 - 60, size.height - 20}, cv::FONT_HERSHEY_SIMPLEX, 0.45, black);
  cv::putText(img, y_label, {5, area.y - 8}, cv::FONT_HERSHEY_SIMPLEX, 0.45, black);
  int legend_y = area.y + 18;
  for (const auto& s : series) {
    if (s.lines)
      for (size_t i = 0; i + 1 < s.x.size(); ++i) cv::line(img, px(s.x[i], s.y[i]), px(s.x[i + 1], s.y[i + 1]), s.colour, 2, cv::LINE_AA);
    if (s.points)
      for (size_t i = 0; i < s.x.size(); ++i) cv::circle(img, px(s.x[i], s.y[i]), 3, s.colour, cv::FILLED, cv::LINE_AA);
    cv::line(img, {area.x + 10, legend_y - 4}, {area.x + 30, legend_y - 4}, s.colour, 2);
    cv::putText(img, s.label, {area.x + 36, legend_y}, cv::FONT_HERSHEY_SIMPLEX, 0.45, black, 1, cv::LINE_AA);
    legend_y += 18;
  }
  return img;
}

void write_png(const std::string& name, const cv::Mat& image) {
  const std::string path = results_dir() + "/" + name;
  std::vector<uchar> bytes;
  cv::imencode(".png", image, bytes);
  write_file_atomically(path, std::string(bytes.begin(), bytes.end()));
  std::cerr << "wrote " << path << "\n";
}

cv::Mat tile(std::vector<cv::Mat> images, int columns) {
  if (images.empty() || columns < 1) return {};
  while (images.size() % columns != 0) images.push_back(cv::Mat(images[0].size(), images[0].type(), cv::Scalar::all(255)));
  std::vector<cv::Mat> rows;
  for (size_t i = 0; i < images.size(); i += columns) {
    cv::Mat row;
    cv::hconcat(std::vector<cv::Mat>(images.begin() + i, images.begin() + i + columns), row);
    rows.push_back(row);
  }
  cv::Mat grid;
  cv::vconcat(rows, grid);
  return grid;
}

std::string machine_description() {
  std::ifstream cpu("/proc/cpuinfo");
  std::string line, model = "unknown CPU";
  while (std::getline(cpu, line)) {
    if (line.rfind("model name", 0) == 0) {
      model = line.substr(line.find(':') + 2);
      break;
    }
  }
  return model + ", " + std::to_string(std::thread::hardware_concurrency()) + " cores";
}

std::string today() {
  std::time_t t = std::time(nullptr);
  char buf[16];
  std::strftime(buf, sizeof buf, "%Y-%m-%d", std::gmtime(&t));
  return buf;
}

}  // namespace nudge::experiments
