#pragma once
// QT (quality threshold) clustering of 2D table intersects (thesis sec. 6.2.2, after Heyer 1999),
// with the thesis' changes: no recursion (a loop), a cluster is every point within `radius` of a
// seed point, and clusters smaller than `min_fraction` of all points are not returned.
#include <Eigen/Core>

#include <vector>

namespace nudge::geometry {

struct QtParams {
  double radius = 0.010;            // m (thesis: 10 mm)
  double min_fraction = 1.0 / 9.0;  // 9 axes per stereo pair at most: a stable axis gives >= 1/9
  int max_clusters = 0;             // 0: as many as pass min_fraction
};

struct Cluster {
  Eigen::Vector2d centroid = Eigen::Vector2d::Zero();
  std::vector<int> members;  // indices into the input
  int size() const { return static_cast<int>(members.size()); }
};

// Largest cluster first. Each round seeds a candidate at every remaining point, keeps the one with
// most members (ties: the tighter one, then the lower seed index), removes its points and repeats
// until the best candidate is below the minimum size. Throws std::invalid_argument for bad params.
std::vector<Cluster> qt_cluster(const std::vector<Eigen::Vector2d>& points, const QtParams& params = {});

}  // namespace nudge::geometry
