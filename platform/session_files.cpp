#include "platform/session_files.hpp"

#include <algorithm>

#include "engine/assert.hpp"

namespace fire {

Result<SessionWriter> SessionWriter::create(const std::string& dir, std::string_view settings_json, std::string_view rig_json,
                                            std::string_view marks_json, uint32_t log_version) {
  using R = Result<SessionWriter>;
  if (Status s = make_directory(dir); !s) return R::failure(s.error);
  auto names = list_directory(dir);
  if (!names) return R::failure(names.error());
  if (!names->empty()) return R::failure(dir + ": the session folder is not empty (a session is written into a new folder)");
  SessionPaths paths{dir};
  if (Status s = write_file_durable(paths.settings(), settings_json); !s) return R::failure(s.error);
  if (!rig_json.empty())
    if (Status s = write_file_durable(paths.rig(), rig_json); !s) return R::failure(s.error);
  if (!marks_json.empty())
    if (Status s = write_file_durable(paths.marks(), marks_json); !s) return R::failure(s.error);
  auto log = AppendFile::open(paths.log());
  if (!log) return R::failure(log.error());
  SessionWriter w(paths, std::move(*log));
  std::string header = input_log_header(log_version) + '\n';
  if (Status s = w.write(header); !s) return R::failure(s.error);
  if (Status s = w.log_.sync(); !s) return R::failure(s.error);
  if (Status s = sync_directory(dir); !s) return R::failure(s.error);
  return w;
}

Result<SessionWriter> SessionWriter::resume(const SessionContents& session) {
  using R = Result<SessionWriter>;
  auto names = list_directory(session.paths.dir);
  if (!names) return R::failure(names.error());
  for (const std::string& name : *names)
    if (name.find(".fsnap.tmp.") != std::string::npos)
      if (Status s = remove_file(session.paths.file(name)); !s) return R::failure(s.error);
  auto log = AppendFile::open(session.paths.log(), session.log.kept_bytes);
  if (!log) return R::failure(log.error());
  if (log->size() != session.log.kept_bytes)
    return R::failure(session.paths.log() + ": changed since it was read (" + std::to_string(log->size()) + " bytes, " +
                      std::to_string(session.log.kept_bytes) + " expected)");
  SessionWriter w(session.paths, std::move(*log));
  const std::string_view kept = std::string_view(session.log_bytes).substr(0, session.log.kept_bytes);
  w.log_hash_.mix(kept.data(), kept.size());
  w.lines_ = static_cast<uint32_t>(std::count(kept.begin(), kept.end(), '\n'));
  if (!session.log.log.events.empty()) w.last_t_us_ = session.log.log.events.back().t_us;
  w.dirty_ = session.log.kept_bytes > session.log.durable_bytes;
  w.snapshots_.assign(session.snapshot_frames.rbegin(), session.snapshot_frames.rend());
  if (Status s = sync_directory(session.paths.dir); !s) return R::failure(s.error);
  return w;
}

Status SessionWriter::write(std::string_view bytes) {
  if (Status s = log_.append(bytes); !s) return s;
  log_hash_.mix(bytes.data(), bytes.size());
  lines_ += static_cast<uint32_t>(std::count(bytes.begin(), bytes.end(), '\n'));
  return Status::success();
}

Status SessionWriter::append(const InputEvent& event) {
  last_t_us_ = event.t_us;
  dirty_ = true;
  return write(format_event(event));
}

Status SessionWriter::commit() {
  if (!dirty_) return Status::success();
  if (Status s = write(format_durable(last_t_us_, log_.size())); !s) return s;
  if (Status s = log_.sync(); !s) return s;
  dirty_ = false;
  ++commits_;
  return Status::success();
}

Status SessionWriter::write_snapshot(uint64_t frame, std::string_view snapshot) {
  FIRE_ASSERT(!dirty_, "a snapshot follows a commit: the log prefix it names must be on disk first");
  if (Status s = write_file_durable(paths_.snapshot(frame), snapshot); !s) return s;
  snapshots_.push_back(frame);
  while (snapshots_.size() > kSnapshotsKept) {
    if (Status s = remove_file(paths_.snapshot(snapshots_.front())); !s) return s;
    snapshots_.erase(snapshots_.begin());
  }
  return Status::success();
}

Result<SessionContents> read_session(const std::string& dir) {
  using R = Result<SessionContents>;
  if (!is_directory(dir)) return R::failure(dir + ": no such session folder");
  SessionContents c;
  c.paths = {dir};
  auto settings = read_text_file(c.paths.settings());
  if (!settings) return R::failure(settings.error() + " (a session folder holds settings.json, input.log and snapshots)");
  c.settings = std::move(*settings);
  auto log = read_text_file(c.paths.log());
  if (!log) return R::failure(log.error() + " (a session folder holds settings.json, input.log and snapshots)");
  c.log_bytes = std::move(*log);
  auto recovered = recover_input_log(c.log_bytes, c.paths.log());
  if (!recovered) return R::failure(recovered.error());
  c.log = std::move(*recovered);
  auto names = list_directory(dir);
  if (!names) return R::failure(names.error());
  for (const std::string& name : *names) {
    uint64_t frame = 0;
    if (parse_snapshot_name(name, frame)) c.snapshot_frames.push_back(frame);
    if (name == kSessionRig) {
      auto rig = read_text_file(c.paths.rig());
      if (!rig) return R::failure(rig.error());
      c.rig = std::move(*rig);
    }
  }
  std::sort(c.snapshot_frames.rbegin(), c.snapshot_frames.rend());
  return c;
}

std::optional<uint64_t> load_last_good_snapshot(const SessionContents& session,
                                                const std::function<Status(SnapshotReader&)>& load,
                                                std::vector<std::string>& skipped) {
  for (uint64_t frame : session.snapshot_frames) {
    const std::string path = session.paths.snapshot(frame);
    auto bytes = read_text_file(path);
    if (!bytes) {
      skipped.push_back(bytes.error());
      continue;
    }
    if (Status s = load_snapshot(*bytes, path, load); !s) {
      skipped.push_back(s.error);
      continue;
    }
    return frame;
  }
  return std::nullopt;
}

Status load_snapshot(std::string_view file, const std::string& path, const std::function<Status(SnapshotReader&)>& load) {
  auto reader = SnapshotReader::open(file, path);
  if (!reader) return Status::failure(reader.error());
  if (Status s = load(*reader); !s) return Status::failure(path + ": " + s.error);
  return Status::success();
}

}  // namespace fire
