#pragma once
// What every fuzz target shares. A failed property aborts, which libFuzzer reports as a crash and saves
// the input; the replay driver (replay_main.cpp) stops on the same abort.
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>

namespace fire::fuzz {

// The name every target gives its input; errors must start with it so that a person knows which file failed.
inline const std::string kSource = "fuzz-input";

[[noreturn]] inline void fail(const char* what, const char* file, int line) {
  std::fprintf(stderr, "fuzz property failed at %s:%d: %s\n", file, line, what);
  std::abort();
}

// A reader's error names the input and says something about the problem.
inline bool names_input_and_problem(const std::string& error) {
  return error.size() > kSource.size() + 2 && std::string_view(error).starts_with(kSource);
}

}  // namespace fire::fuzz

#define FUZZ_CHECK(cond, what)                                      \
  do {                                                              \
    if (!(cond)) ::fire::fuzz::fail(what " [" #cond "]", __FILE__, __LINE__); \
  } while (0)
