#include "nudge/bus/track_convert.hpp"

#include <stdexcept>

#include "nudge/bus/symmetry_convert.hpp"

namespace nudge::bus {

namespace {

bool all_zero(const symmetry_line_t& l) {
  return l.r == 0 && l.theta == 0 && l.x1 == 0 && l.y1 == 0 && l.x2 == 0 && l.y2 == 0;
}

bool all_zero(const float (&box)[4][2]) {
  for (const auto& corner : box)
    if (corner[0] != 0 || corner[1] != 0) return false;
  return true;
}

void check_motion_mask(const track_t& m) {
  if (m.num_blocks != static_cast<int32_t>(m.motion_mask.size()))
    throw std::invalid_argument("track_t num_blocks " + std::to_string(m.num_blocks) + " disagrees with the " +
                                std::to_string(m.motion_mask.size()) + " motion_mask bytes");
  if (m.num_blocks != 0 && (m.blocks_w <= 0 || m.blocks_h <= 0 ||
                            static_cast<int64_t>(m.blocks_w) * m.blocks_h != m.num_blocks))
    throw std::invalid_argument("track_t blocks_w x blocks_h (" + std::to_string(m.blocks_w) + " x " +
                                std::to_string(m.blocks_h) + ") disagrees with num_blocks " +
                                std::to_string(m.num_blocks));
}

}  // namespace

track_t to_message(const tracking::TrackState& s, int64_t utime, int64_t frame_id, const std::string& camera) {
  track_t m{};
  m.utime = utime;
  m.frame_id = frame_id;
  m.camera = camera;
  m.status = static_cast<int8_t>(s.status);
  m.reason = s.reason;
  m.line = to_message(s.line);  // zeros when there is no estimate
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j) m.covariance[i][j] = static_cast<float>(s.covariance(i, j));
  for (int i = 0; i < 4; ++i) {
    m.box[i][0] = s.has_box ? static_cast<float>(s.box[i].x) : 0.f;
    m.box[i][1] = s.has_box ? static_cast<float>(s.box[i].y) : 0.f;
  }
  m.tracks_started = s.tracks_started;
  m.block_size = s.block_size;
  m.blocks_w = s.blocks.cols;
  m.blocks_h = s.blocks.rows;
  m.num_blocks = static_cast<int32_t>(s.blocks.total());
  m.motion_mask.reserve(m.num_blocks);
  for (int y = 0; y < s.blocks.rows; ++y)
    for (int x = 0; x < s.blocks.cols; ++x) m.motion_mask.push_back(s.blocks.at<uint8_t>(y, x) ? 1 : 0);
  return m;
}

tracking::TrackState from_message(const track_t& m) {
  if (m.status < track_t::STATUS_IDLE || m.status > track_t::STATUS_LOST)
    throw std::invalid_argument("track_t status " + std::to_string(m.status) + " is unknown");
  check_motion_mask(m);
  tracking::TrackState s;
  s.status = static_cast<tracking::TrackStatus>(m.status);
  s.reason = m.reason;
  s.utime = m.utime;
  s.has_estimate = !all_zero(m.line);
  s.line = from_message(m.line);
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j) s.covariance(i, j) = m.covariance[i][j];
  s.has_box = !all_zero(m.box);
  for (int i = 0; i < 4; ++i) s.box[i] = {m.box[i][0], m.box[i][1]};
  s.tracks_started = m.tracks_started;
  s.block_size = m.block_size;
  s.blocks = cv::Mat::zeros(m.num_blocks ? m.blocks_h : 0, m.num_blocks ? m.blocks_w : 0, CV_8U);
  for (int i = 0; i < m.num_blocks; ++i) s.blocks.at<uint8_t>(i / m.blocks_w, i % m.blocks_w) = m.motion_mask[i] ? 1 : 0;
  return s;
}

}  // namespace nudge::bus
