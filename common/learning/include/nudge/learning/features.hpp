#pragma once
// SIFT features of one image (thesis sec. 7.3.2), optionally only those inside a box.
#include <opencv2/core.hpp>

#include <string>
#include <vector>

namespace nudge::learning {

// Keypoints and their SIFT descriptors (CV_32F, one 128-wide row per keypoint).
struct Features {
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;
  // Each keypoint's mean colour, B, G, R (CV_32F, one row per keypoint), over the box its SIFT scale
  // covers: SIFT sees grey levels only, and a label of like shapes in different colours (red, green
  // and blue drops) gives near-equal descriptors that the ratio test cannot tell apart. Empty when
  // the image was grey, or for a database written before colours were kept; a row of -1 is a
  // keypoint whose colour is unknown (keypoint_colours).
  cv::Mat colours;

  int size() const { return static_cast<int>(keypoints.size()); }
  bool empty() const { return keypoints.empty(); }
};

// OpenCV's SIFT settings that matter for small, weakly textured objects. The contrast threshold
// is half OpenCV's (and Lowe's) 0.04: a label a hundred pixels wide in a cluttered scene gives
// about twice the keypoints, and the learned bottles' test images keep more verified matches
// (docs/learning.md); the ratio test and the geometric check keep out what the extra, weaker
// keypoints would add by chance.
struct SiftParams {
  double contrast_threshold = 0.02;  // OpenCV default 0.04
  double edge_threshold = 10;        // OpenCV default
  int octave_layers = 3;             // OpenCV default
  // Local contrast equalisation of the grey image before SIFT (CLAHE, Zuiderveld 1994): the clip
  // limit, 0 for none. SIFT's contrast threshold is absolute, so a dark or glossy label (grey levels
  // within a few tens) gives few keypoints however textured it is; equalising each tile's histogram
  // stretches such a label to the full range. The learner and the recognizer must agree on it.
  double equalise_clip = 0;
  int equalise_tile_px = 64;  // the tiles' size in pixels (the grid follows the image's size)
};

// SIFT on the grey image (BGR or grey, 8-bit). Throws std::invalid_argument for an empty or
// non-8-bit image, or settings SIFT refuses (a threshold not positive, fewer than 1 layer, a
// negative clip limit, a tile under 8 pixels).
Features detect_features(const cv::Mat& image, const SiftParams& params = {});

// Each keypoint's mean B, G, R over its box (side its SIFT size; a keypoint found at a simulated
// tilt covers `class_id / 100` times more rows), CV_32F, one row per keypoint; empty for a grey
// image. Integral images: a few operations per keypoint.
cv::Mat keypoint_colours(const cv::Mat& image, const std::vector<cv::KeyPoint>& keypoints);

// Chromaticity (r, g of r + g + b) of each colour row, CV_32F N x 2: a colour's hue and saturation
// without its brightness, which differs between a view held near the camera and a scene. A row
// whose colour is unknown, or too dark to tell (mean below kMinColourLevel of 255), is (-1, -1);
// rows of -1 for every keypoint when `colours` is empty.
inline constexpr float kMinColourLevel = 24;
cv::Mat chromaticities(const cv::Mat& colours, int rows);

// Whether two chromaticity rows could be the same surface's: within `tolerance` of each other
// (Euclidean); an unknown one agrees with anything.
inline bool chromaticities_agree(const float* a, const float* b, float tolerance) {
  if (a[0] < 0 || b[0] < 0) return true;
  const float dr = a[0] - b[0], dg = a[1] - b[1];
  return dr * dr + dg * dg <= tolerance * tolerance;
}

// "" when `a` and `b` find the same keypoints, else what differs, e.g. "contrast 0.04 against 0.02".
std::string sift_settings_difference(const SiftParams& a, const SiftParams& b);

// The grey image SIFT looks at: the image in grey, equalised when `params.equalise_clip` > 0.
cv::Mat sift_grey(const cv::Mat& image, const SiftParams& params = {});

// SIFT of the image as a camera would see it tilted away about the image's horizontal axis
// (ASIFT's simulated tilt, Morel & Yu 2009, in one direction): the image (only `roi` of it, when
// given) squeezed vertically by `tilt` (1/cos of the tilt angle: 2 is 60 deg), area-averaged so
// that the squeeze does not alias, then SIFT; keypoints mapped back into the image's coordinates
// (y times the squeeze; size and angle as detected). SIFT copes with about 40 deg of foreshortening
// by itself; this finds the keypoints of a surface seen more obliquely than that (a held bottle's
// label, its axis vertical in the image, as it looks when the bottle lies pointing at a camera).
// Each keypoint's class_id is tilt_layer_id(tilt), so that the recognizer's ratio test can tell a
// point's squeezed copy from another point (plain SIFT leaves class_id at -1).
// Throws std::invalid_argument for a tilt below 1 and as detect_features does.
Features detect_features_tilted(const cv::Mat& image, double tilt, const SiftParams& params = {},
                                const cv::Rect& roi = {});
// The class_id of keypoints found at a simulated tilt: the tilt in hundredths; -1 for tilt 1.
int tilt_layer_id(double tilt);
// Whether a keypoint was found at a simulated tilt (its class_id is a tilt layer's, >= 100).
inline bool at_simulated_tilt(const cv::KeyPoint& k) { return k.class_id >= 100; }
// The keypoints and descriptors of `b` after those of `a`.
Features concatenate(const Features& a, const Features& b);
// RootSIFT (Arandjelovic & Zisserman, CVPR 2012): each descriptor row L1-normalised and square-
// rooted, so that the Euclidean distance between two rows is the Hellinger distance between their
// gradient histograms and a few large bins no longer dominate it. Rows come out with unit L2 norm
// (an all-zero row stays zero). Recognition matches these; the database keeps plain SIFT.
cv::Mat root_sift(const cv::Mat& descriptors);

// The box grown by `margin` times its width and height on every side (the thesis' "generous" box,
// allowing for the tilt and shift of an imperfect grasp), clipped to the image.
cv::Rect generous_box(const cv::Rect& box, double margin, cv::Size image_size);

// The features whose keypoint lies inside `box`; an empty box keeps everything.
Features features_inside(const Features& features, const cv::Rect& box);

// The features whose keypoint's disc (radius `support` times half its size, the scale SIFT found it
// at) lies wholly inside the nonzero pixels of `mask` (8-bit, the image's size). A keypoint on the
// mask's outline describes the object's silhouette against what stands behind it, which moves
// with the object from scene to scene; only what lies inside is the object's own surface. An empty
// mask keeps everything. Throws std::invalid_argument when the mask is not 8-bit single-channel
// or `support` is negative.
Features features_on_mask(const Features& features, const cv::Mat& mask, double support);

// The features whose index `keep` marks.
Features select_features(const Features& features, const std::vector<bool>& keep);

}  // namespace nudge::learning
