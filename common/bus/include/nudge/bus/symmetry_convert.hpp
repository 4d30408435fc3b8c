#pragma once
// nudge::symmetry results <-> symmetry_lines_t messages.
#include "nudge/symmetry/detector.hpp"
#include "nudge/symmetry_lines_t.hpp"

namespace nudge::bus {

symmetry_line_t to_message(const symmetry::Line& line);
symmetry_lines_t to_message(const symmetry::Result& result, int64_t utime, int64_t frame_id,
                            const std::string& camera);
symmetry::Line from_message(const symmetry_line_t& msg);

}  // namespace nudge::bus
