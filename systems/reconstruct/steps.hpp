#pragma once
// Steps<T>: a C++20 coroutine that does its work a step at a time, so that a long computation written as
// one function (the fit's three phases, fit.cpp) can be spread over frames without being rewritten as a
// state machine. `co_yield Step{}` suspends the body until its owner resumes it; `co_return value`
// finishes it and leaves the value for the owner. It starts eagerly: the call runs the body up to its
// first co_yield, so what a caller passes by reference may be read there and nowhere after, if the body
// says so. Move-only; destroying it destroys a suspended body with its locals.
#include <coroutine>
#include <exception>
#include <optional>
#include <utility>

#include "engine/assert.hpp"

namespace fire::reconstruct {

struct Step {};

template <class T>
class Steps {
 public:
  struct promise_type {
    std::optional<T> value;
    Steps get_return_object() { return Steps(std::coroutine_handle<promise_type>::from_promise(*this)); }
    std::suspend_never initial_suspend() noexcept { return {}; }
    // Suspended at the end, so that the value lives until the owner lets go.
    std::suspend_always final_suspend() noexcept { return {}; }
    std::suspend_always yield_value(Step) noexcept { return {}; }
    void return_value(T v) { value = std::move(v); }
    // No exceptions inside the frame loop: one escaping the body (only std::bad_alloc can) ends the process.
    void unhandled_exception() noexcept { std::terminate(); }
  };

  Steps() = default;
  Steps(Steps&& other) noexcept : handle_(std::exchange(other.handle_, {})) {}
  Steps& operator=(Steps&& other) noexcept {
    if (this != &other) {
      reset();
      handle_ = std::exchange(other.handle_, {});
    }
    return *this;
  }
  Steps(const Steps&) = delete;
  Steps& operator=(const Steps&) = delete;
  ~Steps() { reset(); }

  bool running() const { return handle_ && !handle_.done(); }
  bool finished() const { return handle_ && handle_.done(); }
  // Runs the body from its last co_yield to its next one or to its end.
  void resume() {
    FIRE_ASSERT(running(), "only a suspended body can be resumed");
    handle_.resume();
  }
  const T& value() const {
    FIRE_ASSERT(finished(), "a body's value exists once it has finished");
    return *handle_.promise().value;
  }

 private:
  explicit Steps(std::coroutine_handle<promise_type> handle) : handle_(handle) {}
  void reset() {
    if (handle_) handle_.destroy();
    handle_ = {};
  }
  std::coroutine_handle<promise_type> handle_;
};

}  // namespace fire::reconstruct
