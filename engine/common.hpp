#pragma once
// Types every part of FIRE shares: the point type and a checked result for the boundaries.
#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <utility>

namespace fire {

using Vec3 = Eigen::Vector3d;

// "No element": the index every pool, map and topology array uses for an absent slot.
inline constexpr uint32_t kNone = 0xFFFFFFFFu;

// A value or the reason there is none. Used where input from outside can be wrong
// (files, devices, user commands); inside the frame loop errors are data, not exceptions.
template <class T>
class [[nodiscard]] Result {
 public:
  Result(T value) : value_(std::move(value)) {}
  static Result failure(std::string why) {
    Result r;
    r.error_ = std::move(why);
    return r;
  }
  bool ok() const { return value_.has_value(); }
  explicit operator bool() const { return ok(); }
  T& value() { return *value_; }
  const T& value() const { return *value_; }
  T* operator->() { return &*value_; }
  const T* operator->() const { return &*value_; }
  T& operator*() { return *value_; }
  const T& operator*() const { return *value_; }
  const std::string& error() const { return error_; }

 private:
  Result() = default;
  std::optional<T> value_;
  std::string error_;
};

// A success carrying nothing, or an error message.
struct [[nodiscard]] Status {
  std::string error;
  bool ok() const { return error.empty(); }
  explicit operator bool() const { return ok(); }
  static Status success() { return {}; }
  static Status failure(std::string why) { return {std::move(why)}; }
};

inline bool is_finite(const Vec3& p) { return p.allFinite(); }

// Length of the diagonal of the axis-aligned box around the points (0 for none): the scale that
// tolerances and error figures are relative to.
inline double bounding_box_diagonal(std::span<const Vec3> points) {
  if (points.empty()) return 0;
  Vec3 lo = points[0], hi = points[0];
  for (const Vec3& p : points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  return (hi - lo).norm();
}

}  // namespace fire
