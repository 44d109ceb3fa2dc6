#pragma once
// RGBA8 images (sRGB-encoded, top row first) and PNG files.
#include <cstdint>
#include <string>
#include <vector>

#include "engine/common.hpp"

namespace fire::render {

struct Image {
  uint32_t width = 0, height = 0;
  std::vector<uint8_t> rgba;  // width * height * 4
  const uint8_t* pixel(uint32_t x, uint32_t y) const { return &rgba[(size_t(y) * width + x) * 4]; }
};

// Writes the image as a PNG, atomically; the message names the path when it cannot be written.
Status write_png(const Image& image, const std::string& path);
Result<Image> read_png(const std::string& path);

}  // namespace fire::render
