#pragma once
// A value or the reason there is none. Geometry on real detections meets degenerate input often
// (parallel planes, lines off the image, axes that miss the table): callers get a reason they can
// log or count, never a NaN.
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>

namespace nudge::geometry {

template <typename T>
class Outcome {
 public:
  static Outcome success(T value) {
    Outcome o;
    o.value_ = std::move(value);
    return o;
  }
  static Outcome failure(std::string reason) {
    Outcome o;
    o.reason_ = std::move(reason);
    return o;
  }

  bool ok() const { return value_.has_value(); }
  explicit operator bool() const { return ok(); }
  const std::string& reason() const { return reason_; }  // empty when ok()

  // Throws std::logic_error carrying the reason when there is no value.
  const T& value() const {
    if (!value_) throw std::logic_error("no value: " + reason_);
    return *value_;
  }
  const T& operator*() const { return value(); }
  const T* operator->() const { return &value(); }

 private:
  Outcome() = default;
  std::optional<T> value_;
  std::string reason_;
};

}  // namespace nudge::geometry
