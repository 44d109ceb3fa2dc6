#include "platform/render/image.hpp"

#include <string_view>

#include "platform/files.hpp"

// stb is C written for many compilers; its implementation trips GCC's -Wextra warnings, which are not ours.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#pragma GCC diagnostic ignored "-Wsign-compare"
#pragma GCC diagnostic ignored "-Wunused-parameter"
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wimplicit-fallthrough"
#define STB_IMAGE_WRITE_IMPLEMENTATION
#define STBI_WRITE_NO_STDIO  // files are written atomically by platform/files
#include <stb/stb_image_write.h>
#define STB_IMAGE_IMPLEMENTATION
#define STBI_ONLY_PNG
#include <stb/stb_image.h>
#pragma GCC diagnostic pop

namespace fire::render {

namespace {
void append(void* context, void* data, int size) {
  static_cast<std::string*>(context)->append(static_cast<const char*>(data), size_t(size));
}
}  // namespace

Status write_png(const Image& image, const std::string& path) {
  std::string png;
  if (!stbi_write_png_to_func(append, &png, int(image.width), int(image.height), 4, image.rgba.data(),
                              int(image.width * 4)))
    return Status::failure(path + ": could not encode the PNG");
  return write_file_atomic(path, png);
}

Result<Image> read_png(const std::string& path) {
  auto bytes = read_text_file(path);
  if (!bytes) return Result<Image>::failure(bytes.error());
  int w = 0, h = 0, channels = 0;
  stbi_uc* data = stbi_load_from_memory(reinterpret_cast<const stbi_uc*>(bytes->data()), int(bytes->size()), &w, &h,
                                        &channels, 4);
  if (!data) return Result<Image>::failure(path + ": not a PNG image (" + stbi_failure_reason() + ")");
  Image image{uint32_t(w), uint32_t(h), std::vector<uint8_t>(data, data + size_t(w) * size_t(h) * 4)};
  stbi_image_free(data);
  return image;
}

}  // namespace fire::render
