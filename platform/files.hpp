#pragma once
// File access for every command: whole-file reads and atomic writes (temporary file, then rename),
// so an interrupted or failed export never leaves a partial file behind; durable writes and appends
// (fsync of the file, and of its folder where a name was made) for the session folder.
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "engine/common.hpp"

namespace fire {

Result<std::string> read_text_file(const std::string& path);
// Writes `data` to `path` atomically; on failure nothing at `path` changes.
Status write_file_atomic(const std::string& path, std::string_view data);
// write_file_atomic, then an fsync of the folder, so the new name survives a power cut too.
Status write_file_durable(const std::string& path, std::string_view data);

// Makes the folder `path` (its parent must exist); fine when it already exists as a folder.
Status make_directory(const std::string& path);
bool is_directory(const std::string& path);
// The names in a folder (no "." and ".."), sorted.
Result<std::vector<std::string>> list_directory(const std::string& path);
// fsync of a folder: the names created, renamed or removed in it reach the disk.
Status sync_directory(const std::string& path);
Status remove_file(const std::string& path);

// The extension of a file name, lower case and without the dot ("" when it has none): what the exporters and
// readers choose a format by.
std::string file_extension(const std::string& path);

// A file of the data FIRE bundles (the meshes, under tests/data/ in the repository and share/fire/ once
// installed), found from the running executable, so no path is compiled in: in its folder or up to three
// above it, `share/fire/RELATIVE` (an install: bin/fire) or `tests/data/RELATIVE` (a checkout: build/fire,
// or a test under build/tests/). The error names the file and where it looked.
Result<std::string> bundled_data_file(const std::string& relative);
// The default object of the simulated person and of the fake rig: the pawn.
inline constexpr const char* kDefaultMesh = "meshes/pawn.obj";

// A file that only grows, written with write(2): what was appended is in the kernel as soon as append()
// returns (a killed process loses none of it) and on the disk once sync() returns (a power cut loses none).
class AppendFile {
 public:
  // Opens `path` for appending, creating it when missing; `truncate_to` cuts it first (a torn tail).
  static Result<AppendFile> open(const std::string& path, uint64_t truncate_to = UINT64_MAX);
  AppendFile(AppendFile&& other) noexcept;
  AppendFile& operator=(AppendFile&& other) noexcept;
  AppendFile(const AppendFile&) = delete;
  AppendFile& operator=(const AppendFile&) = delete;
  ~AppendFile();

  Status append(std::string_view data);
  Status sync();
  uint64_t size() const { return size_; }
  const std::string& path() const { return path_; }

 private:
  AppendFile(int fd, std::string path, uint64_t size) : fd_(fd), path_(std::move(path)), size_(size) {}
  int fd_ = -1;
  std::string path_;
  uint64_t size_ = 0;
};

}  // namespace fire
