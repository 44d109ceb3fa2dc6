#include "platform/files.hpp"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <utility>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace fire {

Result<std::string> read_text_file(const std::string& path) {
  // An ifstream opens a folder and reads nothing from it: the file would pass for an empty one.
  if (is_directory(path)) return Result<std::string>::failure(path + ": is a folder, not a file");
  std::ifstream in(path, std::ios::binary);
  if (!in) return Result<std::string>::failure(path + ": cannot open (" + std::strerror(errno) + ")");
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) return Result<std::string>::failure(path + ": read error");
  return ss.str();
}

Status write_file_atomic(const std::string& path, std::string_view data) {
  std::string tmp = path + ".tmp." + std::to_string(::getpid());
  FILE* f = std::fopen(tmp.c_str(), "wb");
  if (!f) return Status::failure(path + ": cannot write (" + std::strerror(errno) + ")");
  bool ok = std::fwrite(data.data(), 1, data.size(), f) == data.size();
  ok = (std::fflush(f) == 0) && ok;
  ok = (::fsync(::fileno(f)) == 0) && ok;
  ok = (std::fclose(f) == 0) && ok;
  if (!ok) {
    std::remove(tmp.c_str());
    return Status::failure(path + ": write failed (" + std::strerror(errno) + ")");
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    int err = errno;
    std::remove(tmp.c_str());
    return Status::failure(path + ": cannot replace (" + std::strerror(err) + ")");
  }
  return Status::success();
}

Status write_file_durable(const std::string& path, std::string_view data) {
  if (Status s = write_file_atomic(path, data); !s) return s;
  const std::string folder = std::filesystem::path(path).parent_path().string();
  return sync_directory(folder.empty() ? "." : folder);
}

Status make_directory(const std::string& path) {
  if (::mkdir(path.c_str(), 0777) == 0 || (errno == EEXIST && is_directory(path))) return Status::success();
  return Status::failure(path + ": cannot make the folder (" + std::strerror(errno) + ")");
}

bool is_directory(const std::string& path) {
  struct stat st;
  return ::stat(path.c_str(), &st) == 0 && S_ISDIR(st.st_mode);
}

Result<std::vector<std::string>> list_directory(const std::string& path) {
  std::error_code ec;
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(path, ec)) names.push_back(entry.path().filename().string());
  if (ec) return Result<std::vector<std::string>>::failure(path + ": cannot list the folder (" + ec.message() + ")");
  std::sort(names.begin(), names.end());
  return names;
}

Status sync_directory(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return Status::failure(path + ": cannot open the folder to sync it (" + std::strerror(errno) + ")");
  const bool ok = ::fsync(fd) == 0;
  const int err = errno;
  ::close(fd);
  if (!ok) return Status::failure(path + ": fsync of the folder failed (" + std::strerror(err) + ")");
  return Status::success();
}

Status remove_file(const std::string& path) {
  if (::unlink(path.c_str()) == 0) return Status::success();
  return Status::failure(path + ": cannot remove (" + std::strerror(errno) + ")");
}

Result<AppendFile> AppendFile::open(const std::string& path, uint64_t truncate_to) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0666);
  auto fail = [&](const char* what) {
    const int err = errno;
    if (fd >= 0) ::close(fd);
    return Result<AppendFile>::failure(path + ": " + what + " (" + std::strerror(err) + ")");
  };
  if (fd < 0) return fail("cannot open for appending");
  struct stat st;
  if (::fstat(fd, &st) != 0) return fail("cannot read its size");
  uint64_t size = static_cast<uint64_t>(st.st_size);
  if (truncate_to < size) {
    if (::ftruncate(fd, static_cast<off_t>(truncate_to)) != 0 || ::fsync(fd) != 0) return fail("cannot cut off the torn tail");
    size = truncate_to;
  }
  return AppendFile(fd, path, size);
}

AppendFile::AppendFile(AppendFile&& other) noexcept
    : fd_(std::exchange(other.fd_, -1)), path_(std::move(other.path_)), size_(other.size_) {}

AppendFile& AppendFile::operator=(AppendFile&& other) noexcept {
  if (this != &other) {
    if (fd_ >= 0) ::close(fd_);
    fd_ = std::exchange(other.fd_, -1);
    path_ = std::move(other.path_);
    size_ = other.size_;
  }
  return *this;
}

AppendFile::~AppendFile() {
  if (fd_ >= 0) ::close(fd_);
}

Status AppendFile::append(std::string_view data) {
  while (!data.empty()) {
    const ssize_t n = ::write(fd_, data.data(), data.size());
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return Status::failure(path_ + ": write failed (" + std::strerror(errno) + ")");
    data.remove_prefix(static_cast<size_t>(n));
    size_ += static_cast<uint64_t>(n);
  }
  return Status::success();
}

Status AppendFile::sync() {
  if (::fdatasync(fd_) != 0) return Status::failure(path_ + ": fsync failed (" + std::strerror(errno) + ")");
  return Status::success();
}

std::string file_extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  if (!ext.empty()) ext.erase(0, 1);
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return ext;
}

Result<std::string> bundled_data_file(const std::string& relative) {
  std::error_code ec;
  std::filesystem::path dir = std::filesystem::read_symlink("/proc/self/exe", ec).parent_path();
  if (ec) return Result<std::string>::failure(relative + ": cannot find the running executable (/proc/self/exe: " + ec.message() + ")");
  std::string looked;
  for (int up = 0; up <= 3 && !dir.empty(); ++up, dir = dir.parent_path()) {
    for (const char* root : {"share/fire", "tests/data"}) {
      const std::filesystem::path candidate = dir / root / relative;
      if (std::filesystem::is_regular_file(candidate, ec)) return candidate.lexically_normal().string();
      looked += (looked.empty() ? "" : ", ") + candidate.string();
    }
    if (dir == dir.root_path()) break;
  }
  return Result<std::string>::failure(relative + ": not found beside the executable (looked in " + looked + ")");
}

}  // namespace fire
