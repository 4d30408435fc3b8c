#include "nudge/bus/symmetry_convert.hpp"

namespace nudge::bus {

symmetry_line_t to_message(const symmetry::Line& l) {
  symmetry_line_t m;
  m.r = static_cast<float>(l.r);
  m.theta = static_cast<float>(l.theta);
  m.votes = static_cast<float>(l.votes);
  m.x1 = static_cast<float>(l.end1.x);
  m.y1 = static_cast<float>(l.end1.y);
  m.x2 = static_cast<float>(l.end2.x);
  m.y2 = static_cast<float>(l.end2.y);
  m.seg_x1 = static_cast<float>(l.seg1.x);
  m.seg_y1 = static_cast<float>(l.seg1.y);
  m.seg_x2 = static_cast<float>(l.seg2.x);
  m.seg_y2 = static_cast<float>(l.seg2.y);
  m.skew = static_cast<float>(l.skew);
  return m;
}

symmetry_lines_t to_message(const symmetry::Result& result, int64_t utime, int64_t frame_id,
                            const std::string& camera) {
  symmetry_lines_t m;
  m.utime = utime;
  m.frame_id = frame_id;
  m.camera = camera;
  m.width = result.width;
  m.height = result.height;
  m.num_edges = result.num_edges;
  m.ms_edges = static_cast<float>(result.ms.edges_ms);
  m.ms_vote = static_cast<float>(result.ms.vote_ms);
  m.ms_peaks = static_cast<float>(result.ms.peaks_ms);
  for (const auto& l : result.lines) m.lines.push_back(to_message(l));
  m.num_lines = static_cast<int32_t>(m.lines.size());
  return m;
}

symmetry::Line from_message(const symmetry_line_t& m) {
  symmetry::Line l;
  l.r = m.r;
  l.theta = m.theta;
  l.votes = m.votes;
  l.skew = m.skew;
  l.end1 = {m.x1, m.y1};
  l.end2 = {m.x2, m.y2};
  l.seg1 = {m.seg_x1, m.seg_y1};
  l.seg2 = {m.seg_x2, m.seg_y2};
  return l;
}

}  // namespace nudge::bus
