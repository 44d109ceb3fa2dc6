#pragma once
// FNV-1a 64 over bytes: the replay hash of pools and surfaces, identical on every run and machine.
#include <cstddef>
#include <cstdint>
#include <vector>

namespace fire {

struct Fnv1a {
  uint64_t value = 0xcbf29ce484222325ull;
  void mix(const void* data, size_t n) {
    auto* b = static_cast<const unsigned char*>(data);
    for (size_t i = 0; i < n; ++i) {
      value ^= b[i];
      value *= 0x100000001b3ull;
    }
  }
  // The element count, then the elements' bytes.
  template <class T>
  void mix_array(const std::vector<T>& v) {
    const uint64_t n = v.size();
    mix(&n, sizeof n);
    if (n) mix(v.data(), n * sizeof(T));
  }
};

}  // namespace fire
