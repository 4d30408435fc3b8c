#pragma once
// nudge::geometry stereo axes <-> axes_t messages.
#include <cstdint>

#include "nudge/axes_t.hpp"
#include "nudge/geometry/interesting_locations.hpp"

namespace nudge::bus {

// One valid axis, in the table frame when `table` is given (its ends and table point; the angle
// from the table's normal), else in the right camera's frame with NaN table point and angle.
axis3d_t to_message(const geometry::PairedAxis& axis, const geometry::TableFrame* table);
axes_t to_message(const geometry::PairingResult& result, int64_t utime, const geometry::TableFrame* table);

// The axes as sent, in the frame they were sent in: `hit` is set when the table point is finite
// (its range from the camera is not sent: 0). Throws std::invalid_argument when num_axes
// disagrees with the axes sent.
geometry::PairedAxis from_message(const axis3d_t& message);
geometry::PairingResult from_message(const axes_t& message);

}  // namespace nudge::bus
