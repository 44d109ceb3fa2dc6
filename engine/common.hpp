#pragma once
// Types every part of FIRE shares: the point type and a checked result for the boundaries.
#include <Eigen/Core>
#include <optional>
#include <string>
#include <utility>

namespace fire {

using Vec3 = Eigen::Vector3d;

// A value or the reason there is none. Used where input from outside can be wrong
// (files, devices, user commands); inside the frame loop errors are data, not exceptions.
template <class T>
class Result {
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
struct Status {
  std::string error;
  bool ok() const { return error.empty(); }
  explicit operator bool() const { return ok(); }
  static Status success() { return {}; }
  static Status failure(std::string why) { return {std::move(why)}; }
};

inline bool is_finite(const Vec3& p) { return p.allFinite(); }

}  // namespace fire
