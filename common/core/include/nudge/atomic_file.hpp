#pragma once
#include <string>

namespace nudge {

// Writes `contents` to `path` atomically: a temporary file in the same directory, flushed and
// fsync'ed, then renamed over the target. A crash mid-write leaves the old file intact.
// Throws std::runtime_error naming the path on failure.
void write_file_atomically(const std::string& path, const std::string& contents);

}  // namespace nudge
