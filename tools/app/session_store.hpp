#pragma once
// A World in the session folder of engine/SESSION.md: its settings, a replay that writes the input log
// durably with snapshots on the way, and reopening after a crash (last good snapshot, then the log's tail).
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "engine/session_dir.hpp"
#include "platform/session_files.hpp"
#include "tools/app/session.hpp"

namespace fire {

// settings.json: what the systems run with (snap distance, close samples, surface on/off and its options).
std::string settings_json(const World& w);
Status apply_settings_json(std::string_view json, const std::string& source, World& w);

// The snapshot file of `w` after a frame ran (before the next one begins), continuing from the session
// log's first `log_bytes` bytes, whose FNV-1a 64 is `log_hash`.
std::string snapshot_world(const World& w, uint64_t log_bytes, uint64_t log_hash);
// Loads a snapshot into `w` (settings applied, no frame run yet) whose log is the recovered `session`
// log: the state, the snapping index rebuilt, the cursor on the first event after the snapshot's prefix
// and the next frame begun, ready for continue_replay. Fails, naming the problem, on a prefix the log does not have or content that does not load.
Status load_world_snapshot(SnapshotReader& in, const SessionContents& session, World& w);

struct SessionWriteOptions {
  // After each commit: the pen-ups and commands now known to be on disk.
  using Commit = std::function<void(uint64_t committed_ups, uint64_t committed_commands)>;
  uint64_t snapshot_every = 0;  // frames between snapshots (0: none); a last one when the replay ends
  Commit on_commit;
  // After each snapshot is on disk, with the frame it was taken after.
  std::function<void(uint64_t frame)> on_snapshot;
};

// Writes a running world's session frame by frame, for a replay or the app: call before_frame before each
// frame runs and after_frame after it (before the next frame begins). Each event the frame delivers is
// appended to the log first (and takes its line there), the log is committed whenever those events hold
// a pen-up or a command, and a snapshot follows every `snapshot_every` frames and the `last` frame.
// Stops writing at the first failed write and keeps its error.
class SessionRecorder {
 public:
  // `w`'s events before its cursor are in `out`'s log already (a new world has none; a reopened one all).
  SessionRecorder(const World& w, SessionWriter& out, SessionWriteOptions options);
  void before_frame(World& w);
  void after_frame(const World& w, bool last);
  // Commits what was appended since the last commit; the first failed write, if any.
  Status finish();
  const Status& status() const { return status_; }
  // Events of the world's log appended so far, counting those it has forgotten (InputLog::forgotten).
  uint64_t appended() const { return appended_; }

 private:
  void commit();
  SessionWriter& out_;
  SessionWriteOptions options_;
  Status status_;
  uint64_t appended_ = 0, ups_ = 0, commands_ = 0, last_snapshot_ = 0;
};

// replay_headless, writing a session: each event is appended to the log before the frame that delivers
// it, the log is committed (durability record, fsync) whenever those events hold a pen-up or a command,
// and a snapshot follows every `snapshot_every` frames and the last frame. Each event's `line` becomes its
// line in the session log. A world reopened from `out`'s session (reopen_session, SessionWriter::resume)
// continues where it stands instead: events added to its log after the recovered ones are written and run. Stops writing at the first failed write and
// returns it (the replay itself runs on).
Status replay_into_session(World& w, Scheduler& scheduler, SessionWriter& out, const SessionWriteOptions& options);

// A log no frame has run yet (a simulator's) written as a new session folder: `w`'s settings, a copy of
// the rig and of the marks when given, every event appended, committed at each pen-up and command, every
// 1,000 events and at the end. No snapshot: reopening replays it from its start.
Status write_log_session(const std::string& dir, const World& w, std::span<const InputEvent> events,
                         std::string_view rig_json, std::string_view marks_json = {});

// The input log of a file, or of a session folder (its input.log, a torn last record dropped and said in
// `notes`), for the commands that read logs without running the frame's systems over them.
Result<InputLog> read_log_or_session(const std::string& path, std::vector<std::string>& notes);

struct ReopenedSession {
  std::unique_ptr<World> world;
  std::unique_ptr<Scheduler> scheduler;
  RecoveredLog log_info;                 // what recovery kept and dropped (the events are in world->log)
  std::optional<uint64_t> snapshot;      // the frame of the snapshot used, none when replayed from the start
  size_t events_replayed = 0;            // the tail replayed after the snapshot
  std::vector<std::string> notes;        // torn tail dropped, snapshots passed over: one line each
};

// Reopens a session folder after a clean exit or a crash: the state a clean replay of the surviving log
// gives. Errors (no folder, no log, corruption before the log's last line, bad settings) name the file.
Result<ReopenedSession> reopen_session(const std::string& dir, Scheduler::Clock clock);

}  // namespace fire
