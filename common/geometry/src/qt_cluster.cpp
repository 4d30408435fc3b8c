#include "nudge/geometry/qt_cluster.hpp"

#include <cmath>
#include <stdexcept>

namespace nudge::geometry {

namespace {

struct Candidate {
  int seed = -1;
  std::vector<int> members;
  double spread = 0;  // sum of squared distances to the seed: breaks ties towards tighter clusters
};

Candidate grow(const std::vector<Eigen::Vector2d>& points, const std::vector<int>& remaining, int seed,
               double radius) {
  Candidate c;
  c.seed = seed;
  const double r2 = radius * radius;
  for (int j : remaining) {
    const double d2 = (points[j] - points[seed]).squaredNorm();
    if (d2 <= r2) {
      c.members.push_back(j);
      c.spread += d2;
    }
  }
  return c;
}

// Spreads closer than `tie` count as equal, so rounding does not decide between equal clusters.
bool better(const Candidate& a, const Candidate& b, double tie) {
  if (a.members.size() != b.members.size()) return a.members.size() > b.members.size();
  if (std::fabs(a.spread - b.spread) > tie) return a.spread < b.spread;
  return a.seed < b.seed;
}

}  // namespace

std::vector<Cluster> qt_cluster(const std::vector<Eigen::Vector2d>& points, const QtParams& params) {
  if (!(params.radius > 0) || !std::isfinite(params.radius))
    throw std::invalid_argument("QT clustering radius must be a positive number");
  if (!(params.min_fraction >= 0 && params.min_fraction <= 1))
    throw std::invalid_argument("QT clustering min_fraction must be in [0, 1]");
  if (params.max_clusters < 0) throw std::invalid_argument("QT clustering max_clusters must be >= 0");

  std::vector<int> remaining;
  for (int i = 0; i < static_cast<int>(points.size()); ++i)
    if (points[i].allFinite()) remaining.push_back(i);
  // The minimum size is a fraction of *all* intersects (thesis), at least one point.
  const double min_size = std::max(1.0, params.min_fraction * static_cast<double>(points.size()) - 1e-9);

  std::vector<Cluster> clusters;
  while (!remaining.empty() && (params.max_clusters == 0 || static_cast<int>(clusters.size()) < params.max_clusters)) {
    Candidate best;
    for (int seed : remaining) {
      Candidate c = grow(points, remaining, seed, params.radius);
      if (best.seed < 0 || better(c, best, 1e-9 * params.radius * params.radius)) best = std::move(c);
    }
    if (static_cast<double>(best.members.size()) < min_size) break;
    Cluster cluster;
    for (int i : best.members) cluster.centroid += points[i];
    cluster.centroid /= static_cast<double>(best.members.size());
    cluster.members = best.members;
    clusters.push_back(std::move(cluster));
    // Remove the members (both lists are in increasing index order).
    std::vector<int> rest;
    size_t k = 0;
    for (int i : remaining) {
      if (k < best.members.size() && best.members[k] == i) ++k;
      else rest.push_back(i);
    }
    remaining.swap(rest);
  }
  return clusters;
}

}  // namespace nudge::geometry
