#pragma once
// Ground-truth images on disk. Surface coordinates (World::render_surface(): CV_32FC3, metres in
// the object's frame, NaN off objects) are stored as 16-bit 3-channel PNGs: channel k holds
// coordinate k as round((c + 0.5 m) / 1 m * 65534) + 1, so 0 marks "no object" and the resolution is
// 15 µm over [-0.5, 0.5] m. Read back with cv::imread(path, cv::IMREAD_UNCHANGED) and decode.
#include <opencv2/core.hpp>

namespace nudge::sim {

// CV_32FC3 -> CV_16UC3 (coordinates outside [-0.5, 0.5] m are clamped).
cv::Mat encode_surface(const cv::Mat& points);
// CV_16UC3 -> CV_32FC3, NaN where the pixel holds 0. Throws std::invalid_argument for another type.
cv::Mat decode_surface(const cv::Mat& encoded);

}  // namespace nudge::sim
