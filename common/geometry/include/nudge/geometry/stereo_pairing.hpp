#pragma once
// Pairs left and right observations of one stereo frame by their shared timestamp. The camera
// stamps both images of a pair with one utime, but the two halves reach a consumer separately and
// either may be lost, so each side waits in a small bounded buffer; whatever can no longer be
// matched is dropped and counted.
#include <cstddef>
#include <cstdint>
#include <map>
#include <optional>
#include <utility>

namespace nudge::geometry {

enum class Side { Left, Right };

template <typename T>
class StereoPairer {
 public:
  struct Pair {
    int64_t utime = 0;
    T left, right;
  };

  // `capacity`: how many unmatched observations each side keeps (oldest dropped first).
  explicit StereoPairer(size_t capacity = 16) : capacity_(capacity < 1 ? 1 : capacity) {}

  // Adds one observation. Returns the completed pair when the other side already holds the same
  // utime; observations older than a completed pair are dropped, since the camera sends pairs in
  // order and their partners are not coming any more. A repeated utime on one side replaces the
  // earlier observation (counted as dropped).
  std::optional<Pair> add(Side side, int64_t utime, T value) {
    auto& mine = side == Side::Left ? left_ : right_;
    auto& other = side == Side::Left ? right_ : left_;
    const auto match = other.find(utime);
    if (match == other.end()) {
      auto [it, inserted] = mine.insert_or_assign(utime, std::move(value));
      (void)it;
      if (!inserted) ++dropped_;
      while (mine.size() > capacity_) {
        mine.erase(mine.begin());
        ++dropped_;
      }
      return std::nullopt;
    }
    Pair pair;
    pair.utime = utime;
    T& partner = match->second;
    pair.left = side == Side::Left ? std::move(value) : std::move(partner);
    pair.right = side == Side::Left ? std::move(partner) : std::move(value);
    other.erase(match);
    drop_before(left_, utime);
    drop_before(right_, utime);
    return pair;
  }

  int64_t dropped() const { return dropped_; }  // unmatched observations discarded so far
  size_t waiting() const { return left_.size() + right_.size(); }

 private:
  void drop_before(std::map<int64_t, T>& buffer, int64_t utime) {
    while (!buffer.empty() && buffer.begin()->first < utime) {
      buffer.erase(buffer.begin());
      ++dropped_;
    }
  }

  size_t capacity_;
  std::map<int64_t, T> left_, right_;
  int64_t dropped_ = 0;
};

}  // namespace nudge::geometry
