#pragma once
// The session folder (engine/SESSION.md): one layout for everything a drawing session leaves on disk,
// and the formats in it. The bytes are made and checked here; platform/session_files.hpp moves them to
// and from the disk (append, fsync, atomic rename), so this file makes no system call.
//
//   DIR/settings.json                 the systems' settings, written once when the session is created
//   DIR/input.log                     the append-only input log (engine/INPUT_LOG.md) with durability records
//   DIR/rig.json, DIR/marks.json      the rig and the marks it was drawn with, when the session has them
//   DIR/snapshot-<frame>.fsnap        snapshots: the state after frame <frame> (20 digits) ran, newest kept
#include <array>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "engine/common.hpp"
#include "engine/hash.hpp"
#include "engine/input_log.hpp"
#include "engine/mesh_index.hpp"
#include "engine/surface.hpp"

namespace fire {

inline constexpr std::string_view kSessionLog = "input.log";
inline constexpr std::string_view kSessionSettings = "settings.json";
inline constexpr std::string_view kSessionRig = "rig.json";
inline constexpr std::string_view kSessionMarks = "marks.json";
// How many snapshots a writer keeps: the newest, and the one before in case the newest is found damaged.
inline constexpr size_t kSnapshotsKept = 2;

struct SessionPaths {
  std::string dir;
  std::string file(std::string_view name) const { return dir + "/" + std::string(name); }
  std::string log() const { return file(kSessionLog); }
  std::string settings() const { return file(kSessionSettings); }
  std::string rig() const { return file(kSessionRig); }
  std::string marks() const { return file(kSessionMarks); }
  std::string snapshot(uint64_t frame) const;
};

// The frame a snapshot file name stands for, or false when `name` is not a snapshot's name.
bool parse_snapshot_name(std::string_view name, uint64_t& frame);

// ---- the log: durability records and recovery after a crash

// `<t_us> meta durable <offset>\n`: written where the log's bytes before `offset` (the record's own first
// byte) are flushed, and followed by an fsync, so once it is on disk everything before it is too.
std::string format_durable(int64_t t_us, uint64_t offset);
inline constexpr std::string_view kDurableKey = "durable";

struct RecoveredLog {
  InputLog log;
  uint64_t kept_bytes = 0;     // the well-formed prefix that was parsed
  uint64_t dropped_bytes = 0;  // a torn last record: bytes after the last end of line
  uint64_t durable_bytes = 0;  // end of the last durability record (0 when there is none)
  uint32_t durable_records = 0;
  uint32_t torn_line = 0;      // the line that was torn (0 when none was)
};

// Reads a session's log that a crash may have cut: an unterminated last line is a torn record and is
// dropped (the writer died or the power went while writing it); anything else malformed is corruption
// and an error naming the line, as is a durability record whose offset is not where it stands.
Result<RecoveredLog> recover_input_log(std::string_view text, const std::string& source);

// ---- snapshots: a checked container of native-endian binary fields
//
//   "FIRE-SNAP 1\n" | u32 0x01020304 (byte order) | u64 payload size | u64 FNV-1a 64 of the payload | payload

inline constexpr std::string_view kSnapshotMagic = "FIRE-SNAP 1\n";
// Where the header's fields lie: the payload size, its checksum, then the payload.
inline constexpr size_t kSnapshotSizeAt = kSnapshotMagic.size() + sizeof(uint32_t);
inline constexpr size_t kSnapshotChecksumAt = kSnapshotSizeAt + sizeof(uint64_t);
inline constexpr size_t kSnapshotHeaderBytes = kSnapshotChecksumAt + sizeof(uint64_t);

// Values written as their bytes: numbers, and typed indices (engine/mesh_index.hpp), which are their number.
template <class T>
inline constexpr bool kSnapshotBytes = std::is_arithmetic_v<T> || kIsIndex<T>;

class SnapshotWriter {
 public:
  template <class T>
    requires std::is_arithmetic_v<T>
  void put(T v) {
    bytes_.append(reinterpret_cast<const char*>(&v), sizeof v);
  }
  template <class Tag>
  void put(Index<Tag> i) {
    put(i.value);
  }
  void put(const Vec3& p) {
    put(p.x());
    put(p.y());
    put(p.z());
  }
  template <class T, size_t N>
  void put(const std::array<T, N>& a) {
    for (const T& x : a) put(x);
  }
  void put(const std::string& s) {
    put(uint64_t(s.size()));
    bytes_ += s;
  }
  template <class T>
  void put(const std::vector<T>& v) {
    put(uint64_t(v.size()));
    if constexpr (kSnapshotBytes<T>) {
      if (!v.empty()) bytes_.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
    } else {
      for (const T& x : v) put(x);
    }
  }
  template <class A, class B>
  void put(const std::pair<A, B>& p) {
    put(p.first);
    put(p.second);
  }
  // The whole file: header, checksum and payload.
  std::string finish() const;

 private:
  std::string bytes_;
};

// Reads what a SnapshotWriter wrote, field by field; the first read past the end (or a count larger than
// what is left) fails this and every later read, so a reader checks ok() once at the end.
class SnapshotReader {
 public:
  // Checks the header, the size and the checksum of a whole snapshot file; `source` names it in errors.
  static Result<SnapshotReader> open(std::string_view file, const std::string& source);

  template <class T>
    requires std::is_arithmetic_v<T>
  bool get(T& v) {
    if (!take(sizeof v)) return false;
    std::memcpy(&v, data_.data() + at_ - sizeof v, sizeof v);
    return true;
  }
  template <class Tag>
  bool get(Index<Tag>& i) {
    return get(i.value);
  }
  bool get(Vec3& p) { return get(p.x()) && get(p.y()) && get(p.z()); }
  template <class T, size_t N>
  bool get(std::array<T, N>& a) {
    for (T& x : a)
      if (!get(x)) return false;
    return true;
  }
  bool get(std::string& s) {
    uint64_t n = 0;
    if (!get(n) || !take_count(n, 1)) return false;
    s.assign(data_.data() + at_ - n, n);
    return true;
  }
  template <class T>
  bool get(std::vector<T>& v) {
    uint64_t n = 0;
    if (!get(n) || !fits(n, kSnapshotBytes<T> ? sizeof(T) : 1)) return false;
    v.resize(n);
    if constexpr (kSnapshotBytes<T>) {
      if (n == 0) return true;
      if (!take(n * sizeof(T))) return false;
      std::memcpy(v.data(), data_.data() + at_ - n * sizeof(T), n * sizeof(T));
      return true;
    } else {
      for (T& x : v)
        if (!get(x)) return false;
      return true;
    }
  }
  template <class A, class B>
  bool get(std::pair<A, B>& p) {
    return get(p.first) && get(p.second);
  }
  // Fails the reader: a field read fine but its value is impossible.
  void fail() { ok_ = false; }
  bool ok() const { return ok_; }
  bool at_end() const { return at_ == data_.size(); }

 private:
  explicit SnapshotReader(std::string_view payload) : data_(payload) {}
  bool fits(uint64_t count, size_t min_bytes) {
    ok_ = ok_ && count <= (data_.size() - at_) / min_bytes;
    return ok_;
  }
  bool take_count(uint64_t count, size_t bytes) { return fits(count, bytes) && take(count * bytes); }
  bool take(size_t n) {
    ok_ = ok_ && n <= data_.size() - at_;
    if (ok_) at_ += n;
    return ok_;
  }
  std::string_view data_;
  size_t at_ = 0;
  bool ok_ = true;
};

// The live surface in a snapshot: the incremental surface equals a full rebuild of the pools only while
// the network is accepted; a refused network keeps the last good surface, so it is stored, not rebuilt.
void save_surface(SnapshotWriter& out, const SurfaceLevels& s);
bool load_surface(SnapshotReader& in, SurfaceLevels& s);

// FNV-1a 64 of the log's first bytes: a snapshot names the log prefix it continues from.
inline uint64_t log_prefix_hash(std::string_view log_bytes) {
  Fnv1a h;
  h.mix(log_bytes.data(), log_bytes.size());
  return h.value;
}

}  // namespace fire
