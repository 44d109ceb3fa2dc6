// Session reader (what reopen_session runs on a session folder's files, less the file system): the
// settings, the log a crash may have torn (recover_input_log) and a snapshot (load_snapshot with
// load_world_snapshot). The input is `settings.json NUL input.log NUL snapshot`. A failed read names
// the input and the problem; a loaded snapshot, written again, loads again to the same world.
//
// A fuzzer cannot forge a 64-bit checksum, so a snapshot whose checksum field is zero gets its payload's
// size and checksum written in before reading, and one whose log hash field is zero the hash of the log
// prefix it names: mutated payloads then reach the fields behind the checksums. Any other value is read
// as written, so the checks themselves are fuzzed too.
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>

#include "platform/session_files.hpp"
#include "tests/fuzz/fuzz_check.hpp"
#include "tools/app/session_store.hpp"

using namespace fire;

namespace {

// The part of `rest` before the next NUL (all of it when there is none); `rest` keeps what follows.
std::string_view take_part(std::string_view& rest) {
  const size_t end = rest.find('\0');
  const std::string_view part = rest.substr(0, end);
  rest = end == std::string_view::npos ? std::string_view() : rest.substr(end + 1);
  return part;
}

uint64_t read_u64(const std::string& bytes, size_t at) {
  uint64_t v = 0;
  std::memcpy(&v, bytes.data() + at, sizeof v);
  return v;
}

void write_u64(std::string& bytes, size_t at, uint64_t v) { std::memcpy(bytes.data() + at, &v, sizeof v); }

// The zero fields filled in, as the header comment says.
void forge_checksums(std::string& file, std::string_view log_bytes) {
  if (file.size() < kSnapshotHeaderBytes + 2 * sizeof(uint64_t) || !std::string_view(file).starts_with(kSnapshotMagic))
    return;
  const size_t prefix_at = kSnapshotHeaderBytes, hash_at = prefix_at + sizeof(uint64_t);
  const uint64_t prefix = read_u64(file, prefix_at);
  if (read_u64(file, hash_at) == 0 && prefix <= log_bytes.size())
    write_u64(file, hash_at, log_prefix_hash(log_bytes.substr(0, prefix)));
  if (read_u64(file, kSnapshotChecksumAt) != 0) return;
  Fnv1a sum;
  sum.mix(file.data() + kSnapshotHeaderBytes, file.size() - kSnapshotHeaderBytes);
  write_u64(file, kSnapshotSizeAt, file.size() - kSnapshotHeaderBytes);
  write_u64(file, kSnapshotChecksumAt, sum.value);
}

// What reopen_session does with one snapshot: a world with the session's settings, the snapshot loaded in.
// A snapshot of a tracked drawing needs a rig: it gets the default one, so its triangulation state is read.
Status load_world(World& w, std::string_view file, const SessionContents& session) {
  auto attempt = [&](bool with_rig) {
    w = World{};
    // Settings that do not read leave the defaults (their error is checked once, by the caller).
    (void)apply_settings_json(session.settings, session.paths.settings(), w);
    if (with_rig) w.rig = TrackingRig{};
    return load_snapshot(file, session.paths.snapshot(0),
                         [&](SnapshotReader& in) { return load_world_snapshot(in, session, w); });
  };
  const Status untracked = attempt(false);
  if (untracked || untracked.error.find("has no rig.json") == std::string::npos) return untracked;
  return attempt(true);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::string_view rest(reinterpret_cast<const char*>(data), size);
  SessionContents session;
  session.paths = {fuzz::kSource};
  session.settings = take_part(rest);
  session.log_bytes = take_part(rest);
  std::string snapshot(rest);

  World first;
  const Status read = apply_settings_json(session.settings, session.paths.settings(), first);
  FUZZ_CHECK(read || fuzz::names_input_and_problem(read.error), "a settings error names the input and the problem");
  auto log = recover_input_log(session.log_bytes, session.paths.log());
  if (!log) {
    FUZZ_CHECK(fuzz::names_input_and_problem(log.error()), "a log error names the input and the problem");
    return 0;
  }
  FUZZ_CHECK(log->kept_bytes + log->dropped_bytes == session.log_bytes.size(), "recovery keeps or drops every byte");
  FUZZ_CHECK(log->durable_bytes <= log->kept_bytes, "the durable prefix is kept");
  session.log = std::move(*log);

  forge_checksums(snapshot, session.log_bytes);
  const Status loaded = load_world(first, snapshot, session);
  if (!loaded) {
    FUZZ_CHECK(fuzz::names_input_and_problem(loaded.error), "a snapshot error names the input and the problem");
    return 0;
  }
  FUZZ_CHECK(first.mesh.validate().empty(), "a loaded snapshot's pools are valid");
  FUZZ_CHECK(first.cursor.next <= first.log.events.size(), "the replay continues inside the log");

  // The state as loaded (a frame begun) is a state the writer can save: it loads again, unchanged.
  const std::string again = snapshot_world(first, read_u64(snapshot, kSnapshotHeaderBytes),
                                           read_u64(snapshot, kSnapshotHeaderBytes + sizeof(uint64_t)));
  World second;
  const Status reloaded = load_world(second, again, session);
  FUZZ_CHECK(reloaded.ok(), "a written snapshot loads");
  FUZZ_CHECK(second.rig.has_value() == first.rig.has_value(), "write -> load keeps the triangulation state");
  FUZZ_CHECK(world_hash(second) == world_hash(first), "write -> load keeps the pools and the surface");
  FUZZ_CHECK(second.cursor.next == first.cursor.next, "write -> load keeps the place in the log");
  return 0;
}
