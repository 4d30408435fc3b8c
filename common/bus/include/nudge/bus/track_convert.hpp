#pragma once
// nudge::tracking results <-> track_t messages.
#include <cstdint>
#include <string>

#include "nudge/track_t.hpp"
#include "nudge/tracking/tracker.hpp"

namespace nudge::bus {

// The state of one camera's tracker for the image (utime, frame_id, camera) it was computed on.
// The line, covariance and box are zeros when the state has none.
track_t to_message(const tracking::TrackState& state, int64_t utime, int64_t frame_id, const std::string& camera);

// What a track_t carries: status, reason, utime, line, covariance, box, motion blocks. The
// estimate and the box count as present when they are not all zeros. Throws
// std::invalid_argument naming the field when the status is unknown or the motion mask's size
// disagrees with num_blocks or blocks_w x blocks_h.
tracking::TrackState from_message(const track_t& message);

}  // namespace nudge::bus
