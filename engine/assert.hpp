#pragma once
// Preconditions as checked assertions: on in debug and sanitizer builds (FIRE_ASSERTIONS defined by
// CMake), compiled out of release builds so the frame loop pays nothing for them.
#include <cstdio>
#include <cstdlib>

#if defined(FIRE_ASSERTIONS) || !defined(NDEBUG)
#define FIRE_ASSERT(cond, why)                                                                        \
  do {                                                                                                \
    if (!(cond)) {                                                                                    \
      std::fprintf(stderr, "%s:%d: assertion failed: %s (%s)\n", __FILE__, __LINE__, #cond, why); \
      std::abort();                                                                                   \
    }                                                                                                 \
  } while (0)
#else
#define FIRE_ASSERT(cond, why) \
  do {                         \
    (void)sizeof(cond);        \
  } while (0)
#endif
