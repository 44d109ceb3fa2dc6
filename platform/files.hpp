#pragma once
// File access for every command: whole-file reads and atomic writes (temporary file, then rename),
// so an interrupted or failed export never leaves a partial file behind.
#include <string>
#include <string_view>

#include "engine/common.hpp"

namespace fire {

Result<std::string> read_text_file(const std::string& path);
// Writes `data` to `path` atomically; on failure nothing at `path` changes.
Status write_file_atomic(const std::string& path, std::string_view data);

}  // namespace fire
