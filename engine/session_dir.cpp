#include "engine/session_dir.hpp"

#include <charconv>
#include <cstdio>

namespace fire {

namespace {

constexpr uint32_t kByteOrderMark = 0x01020304u;
constexpr std::string_view kSnapshotPrefix = "snapshot-", kSnapshotSuffix = ".fsnap";
constexpr size_t kFrameDigits = 20;

}  // namespace

std::string SessionPaths::snapshot(uint64_t frame) const {
  char digits[kFrameDigits + 1];
  std::snprintf(digits, sizeof digits, "%020llu", static_cast<unsigned long long>(frame));
  return file(std::string(kSnapshotPrefix) + digits + std::string(kSnapshotSuffix));
}

bool parse_snapshot_name(std::string_view name, uint64_t& frame) {
  if (name.size() != kSnapshotPrefix.size() + kFrameDigits + kSnapshotSuffix.size() || !name.starts_with(kSnapshotPrefix) ||
      !name.ends_with(kSnapshotSuffix))
    return false;
  const char* first = name.data() + kSnapshotPrefix.size();
  for (size_t k = 0; k < kFrameDigits; ++k)
    if (first[k] < '0' || first[k] > '9') return false;
  auto r = std::from_chars(first, first + kFrameDigits, frame);
  return r.ec == std::errc() && r.ptr == first + kFrameDigits;
}

std::string format_durable(int64_t t_us, uint64_t offset) {
  return std::to_string(t_us) + " meta " + std::string(kDurableKey) + " " + std::to_string(offset) + "\n";
}

Result<RecoveredLog> recover_input_log(std::string_view text, const std::string& source) {
  RecoveredLog out;
  const size_t last_end = text.rfind('\n');
  out.kept_bytes = last_end == std::string_view::npos ? 0 : last_end + 1;
  out.dropped_bytes = text.size() - out.kept_bytes;
  std::string_view kept = text.substr(0, out.kept_bytes);
  // Offsets of line starts, to check each durability record stands where it says it does.
  std::vector<uint64_t> line_start{0};
  for (size_t i = 0; i < kept.size(); ++i)
    if (kept[i] == '\n') line_start.push_back(i + 1);
  if (out.dropped_bytes > 0) out.torn_line = static_cast<uint32_t>(line_start.size());
  if (kept.empty())
    return Result<RecoveredLog>::failure(source + ": nothing recoverable: the log has no complete line (" +
                                         std::to_string(text.size()) + " bytes, header included)");
  auto log = parse_input_log(kept, source);
  if (!log) return Result<RecoveredLog>::failure(log.error());
  out.log = std::move(*log);
  for (const InputEvent& e : out.log.events) {
    if (e.kind != EventKind::Meta || e.name != kDurableKey) continue;
    const uint64_t at = line_start[e.line - 1];
    uint64_t said = 0;
    auto r = std::from_chars(e.text.data(), e.text.data() + e.text.size(), said);
    if (r.ec != std::errc() || r.ptr != e.text.data() + e.text.size() || said != at)
      return Result<RecoveredLog>::failure(source + ":" + std::to_string(e.line) + ": durability record '" + e.text +
                                           "' does not name its own offset " + std::to_string(at) +
                                           " (the log was edited or spliced)");
    out.durable_bytes = line_start[e.line];
    ++out.durable_records;
  }
  return out;
}

std::string SnapshotWriter::finish() const {
  std::string file(kSnapshotMagic);
  Fnv1a h;
  h.mix(bytes_.data(), bytes_.size());
  const uint64_t size = bytes_.size(), sum = h.value;
  file.append(reinterpret_cast<const char*>(&kByteOrderMark), sizeof kByteOrderMark);
  file.append(reinterpret_cast<const char*>(&size), sizeof size);
  file.append(reinterpret_cast<const char*>(&sum), sizeof sum);
  file += bytes_;
  return file;
}

Result<SnapshotReader> SnapshotReader::open(std::string_view file, const std::string& source) {
  auto fail = [&](const std::string& why) { return Result<SnapshotReader>::failure(source + ": " + why); };
  if (file.size() < kSnapshotHeaderBytes || !file.starts_with(kSnapshotMagic)) {
    if (file.starts_with("FIRE-SNAP ")) return fail("unknown snapshot version (this build reads FIRE-SNAP 1)");
    return fail("not a FIRE snapshot or cut inside its header (" + std::to_string(file.size()) + " bytes)");
  }
  uint32_t order = 0;
  uint64_t size = 0, sum = 0;
  std::memcpy(&order, file.data() + kSnapshotMagic.size(), sizeof order);
  std::memcpy(&size, file.data() + kSnapshotSizeAt, sizeof size);
  std::memcpy(&sum, file.data() + kSnapshotChecksumAt, sizeof sum);
  if (order != kByteOrderMark) return fail("written on a machine of the other byte order");
  const std::string_view payload = file.substr(kSnapshotHeaderBytes);
  if (payload.size() != size)
    return fail("payload is " + std::to_string(payload.size()) + " bytes, the header says " + std::to_string(size) +
                " (cut off or extended)");
  Fnv1a h;
  h.mix(payload.data(), payload.size());
  if (h.value != sum) return fail("checksum mismatch (the snapshot is damaged)");
  return SnapshotReader(payload);
}

namespace {

// The surface's fields as the file holds them, one list for the writer and the reader; `settled` follows as a byte.
template <class Surface, class Field>
void for_each_surface_field(Surface& s, Field&& field) {
  field(s.level);
  field(s.positions);
  field(s.normals);
  field(s.quads);
  field(s.topology_version);
  field(s.frame);
  field(s.changed.begin);
  field(s.changed.end);
}

}  // namespace

void save_surface(SnapshotWriter& out, const SurfaceLevels& s) {
  for_each_surface_field(s, [&](const auto& value) { out.put(value); });
  out.put(uint8_t(s.settled));
}

bool load_surface(SnapshotReader& in, SurfaceLevels& s) {
  uint8_t settled = 0;
  for_each_surface_field(s, [&](auto& value) { in.get(value); });
  in.get(settled);
  s.settled = settled != 0;
  const size_t n = s.positions.size();
  if (s.normals.size() != n || s.quads.size() % 4 != 0) in.fail();
  for (uint32_t q : s.quads)
    if (q >= n) in.fail();
  return in.ok();
}

}  // namespace fire
