#pragma once
// What a camera's sensor does to a rendered image: Gaussian pixel noise, and the motion blur of a
// shutter that stays open while the scene moves. The World's renders and the camera service's sim
// backend (which blurs before it adds noise) share these, so a simulated camera has one noise model.
#include <opencv2/core.hpp>

#include <random>
#include <vector>

namespace nudge::sim {

// Adds zero-mean Gaussian noise of standard deviation `sigma` (grey levels) to every channel of
// every pixel of `image`, in place, drawing from `rng` in row-major order (so a seed fixes the
// noise). 8-bit images are rounded and saturate at 0 and 255; float images are not clipped, so
// noise can go on an intermediate (e.g. a blurred exposure) before its one conversion to 8 bits.
// sigma <= 0 leaves the image (and `rng`) alone. Throws std::invalid_argument for a depth other
// than CV_8U or CV_32F.
void add_sensor_noise(cv::Mat& image, double sigma, std::mt19937_64& rng);

// The per-pixel mean of `frames`, as a float image (CV_32F with the frames' channel count): the
// exposure of a shutter open across the instants the frames were rendered at. The frames must be
// non-empty and share size and type; std::invalid_argument names the first one that does not.
cv::Mat average_frames(const std::vector<cv::Mat>& frames);

}  // namespace nudge::sim
