#pragma once
// features.bin: every view's keypoints and descriptors, little-endian as the machine writes it,
// ending with an FNV-1a 64-bit checksum of everything before it (private to nudge_learning).
//   "NUDGEFT1" | u32 format version | u32 views | per view: u32 n, u32 dims,
//   n x {f32 x, y, size, angle, response; i32 octave, class_id}, n x dims f32 | u64 checksum
#include <string>
#include <vector>

#include "nudge/learning/features.hpp"

namespace nudge::learning::detail {

std::string encode_features(const std::vector<const Features*>& views, int format_version);
// Throws std::runtime_error saying what is wrong (truncated, bad checksum, newer format, ...).
std::vector<Features> decode_features(const std::string& bytes, int max_format_version);

}  // namespace nudge::learning::detail
