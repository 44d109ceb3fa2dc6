#pragma once
// The session folder of engine/SESSION.md on disk: a writer that appends the input log and makes it
// durable at commit points, writes snapshots atomically and keeps the newest few (and resumes a session
// after a crash); and a reader that recovers the log a crash left and lists the snapshots, newest first. What a snapshot holds is its
// writer's business (tools/app/session_store.hpp for a World).
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "engine/hash.hpp"
#include "engine/session_dir.hpp"
#include "platform/files.hpp"

namespace fire {

struct SessionContents {
  SessionPaths paths;
  std::string settings;   // settings.json as written
  std::string log_bytes;  // the log as found, torn tail included
  std::string rig;        // rig.json as written; empty when the session has none (no device reports)
  RecoveredLog log;
  std::vector<uint64_t> snapshot_frames;  // newest first
};

class SessionWriter {
 public:
  // Makes `dir` (missing or empty) and writes the settings, the rig and the marks (each when given) and the
  // log's header (of `log_version`: the version of the log the session goes on from), durably.
  static Result<SessionWriter> create(const std::string& dir, std::string_view settings_json,
                                      std::string_view rig_json = {}, std::string_view marks_json = {},
                                      uint32_t log_version = kInputLogVersion);
  // Opens a session that read_session recovered for appending after a crash: cuts its torn last record
  // off the log (durably), so the next record starts a line of its own, and removes the temporary files a
  // killed writer left. The records kept count as not yet on disk until the next commit.
  static Result<SessionWriter> resume(const SessionContents& session);

  // Appends one record (format_event); in the kernel when this returns, on disk after the next commit().
  Status append(const InputEvent& event);
  // Appends a durability record and fsyncs the log: everything before the record, and the record, is on
  // disk when this returns. Nothing to do when nothing was appended since the last commit.
  Status commit();
  // Writes `snapshot` (a SnapshotWriter's file) for `frame` atomically and durably, and removes all but
  // the newest kSnapshotsKept snapshots. Call it right after commit(): a snapshot names log_bytes() and
  // log_hash() as the log prefix it continues from, which must be on disk before it.
  Status write_snapshot(uint64_t frame, std::string_view snapshot);

  const SessionPaths& paths() const { return paths_; }
  uint64_t log_bytes() const { return log_.size(); }
  // FNV-1a 64 of the whole log so far (log_prefix_hash of its bytes), kept as it grows.
  uint64_t log_hash() const { return log_hash_.value; }
  uint64_t commits() const { return commits_; }
  uint32_t lines() const { return lines_; }  // lines in the log so far, header included

 private:
  SessionWriter(SessionPaths paths, AppendFile log) : paths_(std::move(paths)), log_(std::move(log)) {}
  Status write(std::string_view bytes);
  SessionPaths paths_;
  AppendFile log_;
  Fnv1a log_hash_;
  int64_t last_t_us_ = 0;
  bool dirty_ = false;
  uint64_t commits_ = 0;
  uint32_t lines_ = 0;
  std::vector<uint64_t> snapshots_;  // frames of the snapshots on disk, oldest first
};


// Reads a session folder: errors name the folder or the file and the problem (no folder, no log, a log
// corrupt before its last line). A torn last record is not an error: RecoveredLog says what was dropped.
Result<SessionContents> read_session(const std::string& dir);

// Tries the snapshots newest first: the first whose file reads, whose checksum holds and which `load`
// accepts is used, and its frame returned; each one passed over adds a line to `skipped` naming the file
// and the problem. None good: nullopt, and the log is replayed from its start.
std::optional<uint64_t> load_last_good_snapshot(const SessionContents& session,
                                                const std::function<Status(SnapshotReader&)>& load,
                                                std::vector<std::string>& skipped);

// One snapshot file's bytes, read by load_last_good_snapshot: its header and checksum checked, then
// `load` run on it; an error names `path` and the problem. No file system call: the session fuzz target
// (tests/fuzz/fuzz_session.cpp) runs it on its input.
Status load_snapshot(std::string_view file, const std::string& path, const std::function<Status(SnapshotReader&)>& load);

}  // namespace fire
