#include "platform/surface_io.hpp"

#include <algorithm>
#include <bit>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <nlohmann/json.hpp>
#include <vector>

#include <Eigen/Geometry>  // cross products

#include "platform/files.hpp"
#include "platform/obj.hpp"

namespace fire {

namespace {

// ---------------------------------------------------------------- little-endian bytes

template <class T>
void put(std::string& out, T value) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  if constexpr (std::endian::native == std::endian::big) std::reverse(bytes, bytes + sizeof(T));
  out.append(bytes, sizeof(T));
}

// The caller has checked that [offset, offset + sizeof(T)) lies inside `bytes`.
template <class T>
T get(std::string_view bytes, size_t offset) {
  char raw[sizeof(T)];
  std::memcpy(raw, bytes.data() + offset, sizeof(T));
  if constexpr (std::endian::native == std::endian::big) std::reverse(raw, raw + sizeof(T));
  T value;
  std::memcpy(&value, raw, sizeof(T));
  return value;
}

void put_vec3f(std::string& out, const Vec3& v) {
  for (int k = 0; k < 3; ++k) put(out, static_cast<float>(v[k]));
}

Vec3 get_vec3f(std::string_view bytes, size_t offset) {
  return {get<float>(bytes, offset), get<float>(bytes, offset + 4), get<float>(bytes, offset + 8)};
}

void append_number(std::string& out, double value) {
  char buf[32];
  auto r = std::to_chars(buf, buf + sizeof buf, value);  // shortest text that reads back to the same double
  out.append(buf, r.ptr);
}

// ---------------------------------------------------------------- checking and normals

Status check_surface(const SurfaceMesh& s, bool needs_float) {
  if (s.positions.empty()) return Status::failure("the surface has no vertices");
  if (s.face_offsets.empty() || s.face_count() == 0) return Status::failure("the surface has no faces");
  if (s.face_offsets.front() != 0 || s.face_offsets.back() != s.face_vertices.size())
    return Status::failure("face offsets do not cover the face vertex list (" +
                           std::to_string(s.face_offsets.back()) + " vs " + std::to_string(s.face_vertices.size()) +
                           ")");
  if (s.positions.size() > static_cast<size_t>(std::numeric_limits<int32_t>::max()))
    return Status::failure("the surface has too many vertices (" + std::to_string(s.positions.size()) + ")");
  if (!s.normals.empty() && s.normals.size() != s.positions.size())
    return Status::failure("the surface has " + std::to_string(s.normals.size()) + " normals for " +
                           std::to_string(s.positions.size()) + " vertices");
  for (size_t f = 0; f < s.face_count(); ++f) {
    if (s.face_offsets[f + 1] < s.face_offsets[f] + 3)
      return Status::failure("face " + std::to_string(f) + " has fewer than 3 vertices");
    if (s.face_offsets[f + 1] > s.face_vertices.size())
      return Status::failure("face " + std::to_string(f) + " runs past the face vertex list");
    for (uint32_t c = s.face_offsets[f]; c < s.face_offsets[f + 1]; ++c) {
      if (s.face_vertices[c] >= s.positions.size())
        return Status::failure("face " + std::to_string(f) + " refers to vertex " + std::to_string(s.face_vertices[c]) +
                               " of " + std::to_string(s.positions.size()));
      for (uint32_t d = s.face_offsets[f]; d < c; ++d)
        if (s.face_vertices[d] == s.face_vertices[c])
          return Status::failure("face " + std::to_string(f) + " uses vertex " + std::to_string(s.face_vertices[c]) +
                                 " twice");
    }
  }
  const double float_max = std::numeric_limits<float>::max();
  for (size_t v = 0; v < s.positions.size(); ++v) {
    if (!is_finite(s.positions[v]))
      return Status::failure("vertex " + std::to_string(v) + " has a non-finite coordinate (NaN or infinity)");
    if (needs_float && s.positions[v].cwiseAbs().maxCoeff() > float_max)
      return Status::failure("vertex " + std::to_string(v) + " has a coordinate beyond the 32-bit float range");
  }
  for (size_t v = 0; v < s.normals.size(); ++v)
    if (!is_finite(s.normals[v]))
      return Status::failure("normal " + std::to_string(v) + " is not finite (NaN or infinity)");
  return Status::success();
}

// Twice the area times the unit normal of a planar polygon (Newell's method, relative to its first
// vertex so that coordinates far from the origin lose no precision).
Vec3 area_normal(const SurfaceMesh& s, size_t f) {
  const uint32_t begin = s.face_offsets[f], end = s.face_offsets[f + 1];
  const Vec3& origin = s.positions[s.face_vertices[begin]];
  Vec3 sum = Vec3::Zero();
  for (uint32_t c = begin + 1; c + 1 < end; ++c)
    sum += (s.positions[s.face_vertices[c]] - origin).cross(s.positions[s.face_vertices[c + 1]] - origin);
  return sum;
}

std::vector<Vec3> export_normals(const SurfaceMesh& s) {
  std::vector<Vec3> from_faces(s.positions.size(), Vec3::Zero());
  for (size_t f = 0; f < s.face_count(); ++f) {
    const Vec3 n = area_normal(s, f);
    for (uint32_t c = s.face_offsets[f]; c < s.face_offsets[f + 1]; ++c) from_faces[s.face_vertices[c]] += n;
  }
  std::vector<Vec3> out(s.positions.size());
  for (size_t v = 0; v < s.positions.size(); ++v) {
    const Vec3 given = s.normals.empty() ? Vec3::Zero() : s.normals[v];
    const Vec3 unit_given = given.normalized(), unit_faces = from_faces[v].normalized();
    // Eigen's normalized() leaves a zero vector zero; a vertex with no face area gets +z so that
    // every written normal is unit length, as glTF requires.
    if (unit_given.squaredNorm() > 0.5)
      out[v] = unit_given;
    else if (unit_faces.squaredNorm() > 0.5)
      out[v] = unit_faces;
    else
      out[v] = Vec3::UnitZ();
  }
  return out;
}

// Fan triangles (v0, vi, vi+1) of every face, as vertex indices.
std::vector<uint32_t> fan_triangles(const SurfaceMesh& s) {
  std::vector<uint32_t> tris;
  tris.reserve(3 * (s.face_vertices.size() - 2 * s.face_count()));
  for (size_t f = 0; f < s.face_count(); ++f)
    for (uint32_t c = s.face_offsets[f] + 1; c + 1 < s.face_offsets[f + 1]; ++c) {
      tris.push_back(s.face_vertices[s.face_offsets[f]]);
      tris.push_back(s.face_vertices[c]);
      tris.push_back(s.face_vertices[c + 1]);
    }
  return tris;
}

// ---------------------------------------------------------------- encoders

std::string encode_obj(const SurfaceMesh& s, const std::vector<Vec3>& normals, LengthUnit unit) {
  std::string out = "# FIRE surface: " + std::to_string(s.positions.size()) + " vertices, " +
                    std::to_string(s.face_count()) + " faces; vertex i has normal i\n# units: " + unit_name(unit) +
                    ", up: +Z\n";
  out.reserve(out.size() + 60 * s.positions.size() * 2 + 12 * s.face_vertices.size());
  auto line3 = [&](const char* tag, const Vec3& p) {
    out += tag;
    for (int k = 0; k < 3; ++k) {
      out += ' ';
      append_number(out, p[k]);
    }
    out += '\n';
  };
  for (const Vec3& p : s.positions) line3("v", p);
  for (const Vec3& n : normals) line3("vn", n);
  for (size_t f = 0; f < s.face_count(); ++f) {
    out += 'f';
    for (uint32_t c = s.face_offsets[f]; c < s.face_offsets[f + 1]; ++c) {
      const std::string index = std::to_string(s.face_vertices[c] + 1);
      out += ' ';
      out += index;
      out += "//";
      out += index;
    }
    out += '\n';
  }
  return out;
}

constexpr std::string_view kPlyVertexHeader =
    "property float x\nproperty float y\nproperty float z\n"
    "property float nx\nproperty float ny\nproperty float nz\n";
constexpr std::string_view kPlyFaceProperty = "property list uchar int vertex_indices\n";

Result<std::string> encode_ply(const SurfaceMesh& s, const std::vector<Vec3>& normals, LengthUnit unit) {
  for (size_t f = 0; f < s.face_count(); ++f)
    if (s.face_size(f) > 255)
      return Result<std::string>::failure("face " + std::to_string(f) + " has " + std::to_string(s.face_size(f)) +
                                          " vertices; a PLY uchar list holds at most 255");
  std::string out = "ply\nformat binary_little_endian 1.0\ncomment FIRE surface\ncomment units " +
                    std::string(unit_name(unit)) + "\ncomment up +Z\nelement vertex " + std::to_string(s.positions.size()) + "\n";
  out += kPlyVertexHeader;
  out += "element face " + std::to_string(s.face_count()) + "\n";
  out += kPlyFaceProperty;
  out += "end_header\n";
  out.reserve(out.size() + 24 * s.positions.size() + s.face_count() + 4 * s.face_vertices.size());
  for (size_t v = 0; v < s.positions.size(); ++v) {
    put_vec3f(out, s.positions[v]);
    put_vec3f(out, normals[v]);
  }
  for (size_t f = 0; f < s.face_count(); ++f) {
    put(out, static_cast<uint8_t>(s.face_size(f)));
    for (uint32_t c = s.face_offsets[f]; c < s.face_offsets[f + 1]; ++c) put(out, static_cast<int32_t>(s.face_vertices[c]));
  }
  return out;
}

constexpr size_t kStlHeaderBytes = 80, kStlTriangleBytes = 50;

Result<std::string> encode_stl(const SurfaceMesh& s, LengthUnit unit) {
  const std::vector<uint32_t> tris = fan_triangles(s);
  const size_t count = tris.size() / 3;
  if (count > std::numeric_limits<uint32_t>::max())
    return Result<std::string>::failure("too many triangles for STL (" + std::to_string(count) + ")");
  // The header must not start with "solid", which would make readers take the file for ASCII STL.
  std::string out = std::string("FIRE binary STL surface; units: ") + unit_name(unit) + "; up: +Z";
  out.resize(kStlHeaderBytes, ' ');
  put(out, static_cast<uint32_t>(count));
  out.reserve(out.size() + kStlTriangleBytes * count);
  for (size_t t = 0; t < count; ++t) {
    const Vec3 &a = s.positions[tris[3 * t]], &b = s.positions[tris[3 * t + 1]], &c = s.positions[tris[3 * t + 2]];
    put_vec3f(out, (b - a).cross(c - a).normalized());  // zero for a degenerate triangle, as STL allows
    put_vec3f(out, a);
    put_vec3f(out, b);
    put_vec3f(out, c);
    put(out, uint16_t{0});
  }
  return out;
}

constexpr uint32_t kGlbMagic = 0x46546C67;      // "glTF"
constexpr uint32_t kGlbJsonChunk = 0x4E4F534A;  // "JSON"
constexpr uint32_t kGlbBinChunk = 0x004E4942;   // "BIN\0"
constexpr int kGlFloat = 5126, kGlUnsignedInt = 5125;

// glTF is +Y up (glTF 2.0, 3.4); FIRE's frame is +Z up. Written turned -90 degrees about X, read turned back,
// so the object stands in Blender and three.js as it stood on the table.
Vec3 to_gltf(const Vec3& p) { return {p.x(), p.z(), -p.y()}; }
Vec3 from_gltf(const Vec3& p) { return {p.x(), -p.z(), p.y()}; }

Result<std::string> encode_glb(const SurfaceMesh& s, const std::vector<Vec3>& normals) {
  const std::vector<uint32_t> tris = fan_triangles(s);
  const size_t vertex_bytes = 12 * s.positions.size(), index_bytes = 4 * tris.size();
  const size_t bin_length = 2 * vertex_bytes + index_bytes;  // every part is a multiple of 4 already

  std::string bin;
  bin.reserve(bin_length);
  Eigen::Vector3f lo = Eigen::Vector3f::Constant(std::numeric_limits<float>::max()), hi = -lo;
  for (const Vec3& p : s.positions) {
    const Vec3 q = to_gltf(p);
    const Eigen::Vector3f pf = q.cast<float>();  // min/max of the values stored, as the validator checks
    lo = lo.cwiseMin(pf);
    hi = hi.cwiseMax(pf);
    put_vec3f(bin, q);
  }
  for (const Vec3& n : normals) put_vec3f(bin, to_gltf(n));
  for (uint32_t i : tris) put(bin, i);

  using json = nlohmann::ordered_json;
  auto vec = [](const Eigen::Vector3f& v) { return json::array({double(v[0]), double(v[1]), double(v[2])}); };
  json doc;
  doc["asset"] = {{"version", "2.0"}, {"generator", "FIRE"}};
  doc["scene"] = 0;
  doc["scenes"] = json::array({{{"nodes", {0}}}});
  doc["nodes"] = json::array({{{"mesh", 0}}});
  doc["meshes"] = json::array(
      {{{"primitives", json::array({{{"attributes", {{"POSITION", 0}, {"NORMAL", 1}}}, {"indices", 2}, {"mode", 4}}})}}});
  doc["buffers"] = json::array({{{"byteLength", bin_length}}});
  doc["bufferViews"] = json::array({
      {{"buffer", 0}, {"byteOffset", 0}, {"byteLength", vertex_bytes}, {"target", 34962}},
      {{"buffer", 0}, {"byteOffset", vertex_bytes}, {"byteLength", vertex_bytes}, {"target", 34962}},
      {{"buffer", 0}, {"byteOffset", 2 * vertex_bytes}, {"byteLength", index_bytes}, {"target", 34963}},
  });
  doc["accessors"] = json::array({
      {{"bufferView", 0}, {"componentType", kGlFloat}, {"count", s.positions.size()}, {"type", "VEC3"},
       {"min", vec(lo)}, {"max", vec(hi)}},
      {{"bufferView", 1}, {"componentType", kGlFloat}, {"count", s.positions.size()}, {"type", "VEC3"}},
      {{"bufferView", 2}, {"componentType", kGlUnsignedInt}, {"count", tris.size()}, {"type", "SCALAR"}},
  });
  std::string text = doc.dump();
  text.resize((text.size() + 3) / 4 * 4, ' ');  // the spec pads the JSON chunk with spaces

  const size_t total = 12 + 8 + text.size() + 8 + bin.size();
  if (total > std::numeric_limits<uint32_t>::max())
    return Result<std::string>::failure("the surface is too large for a .glb file (" + std::to_string(total) +
                                        " bytes; the limit is 4 GiB)");
  std::string out;
  out.reserve(total);
  put(out, kGlbMagic);
  put(out, uint32_t{2});
  put(out, static_cast<uint32_t>(total));
  put(out, static_cast<uint32_t>(text.size()));
  put(out, kGlbJsonChunk);
  out += text;
  put(out, static_cast<uint32_t>(bin.size()));
  put(out, kGlbBinChunk);
  out += bin;
  return out;
}

// ---------------------------------------------------------------- decoders

std::vector<std::string_view> split_fields(std::string_view line) {
  std::vector<std::string_view> out;
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && std::isspace(static_cast<unsigned char>(line[i]))) ++i;
    size_t j = i;
    while (j < line.size() && !std::isspace(static_cast<unsigned char>(line[j]))) ++j;
    if (j > i) out.push_back(line.substr(i, j - i));
    i = j;
  }
  return out;
}

// The unit a FIRE file names after `key` in `text` (a header line or comment): metres when it names none.
Result<LengthUnit> named_unit(std::string_view text, std::string_view key, const std::string& source) {
  const size_t at = text.find(key);
  if (at == std::string_view::npos) return LengthUnit::Metre;
  size_t begin = at + key.size();
  while (begin < text.size() && text[begin] == ' ') ++begin;
  size_t end = begin;
  while (end < text.size() && std::isalpha(static_cast<unsigned char>(text[end]))) ++end;
  auto unit = length_unit_of(text.substr(begin, end - begin));
  if (!unit) return Result<LengthUnit>::failure(source + ": " + unit.error());
  return unit;
}

// Divided by the exact count of units in a metre, the one rounding a reader adds to the writer's.
Result<SurfaceMesh> in_metres(SurfaceMesh s, LengthUnit unit) {
  if (unit != LengthUnit::Metre)
    for (Vec3& p : s.positions) p /= units_per_metre(unit);
  return s;
}

Result<SurfaceMesh> decode_obj(std::string_view text, const std::string& source) {
  auto polygons = parse_obj(text, source);
  if (!polygons) return Result<SurfaceMesh>::failure(polygons.error());
  SurfaceMesh s;
  s.positions = std::move(polygons->positions);
  s.face_offsets = std::move(polygons->face_offsets);
  s.face_vertices = std::move(polygons->face_vertices);
  // parse_obj skips `vn`; read them here and keep them when they pair up with the vertices.
  std::vector<Vec3> normals;
  size_t pos = 0, line_no = 0;
  while (pos < text.size()) {
    size_t end = std::min(text.find('\n', pos), text.size());
    std::string_view line = text.substr(pos, end - pos);
    pos = end + 1;
    ++line_no;
    auto f = split_fields(line);
    if (f.empty() || f[0] != "vn") continue;
    Vec3 n;
    if (f.size() < 4)
      return Result<SurfaceMesh>::failure(source + ":" + std::to_string(line_no) + ": normal needs three coordinates");
    for (int k = 0; k < 3; ++k) {
      auto r = std::from_chars(f[1 + k].data(), f[1 + k].data() + f[1 + k].size(), n[k]);
      if (r.ec != std::errc() || r.ptr != f[1 + k].data() + f[1 + k].size() || !std::isfinite(n[k]))
        return Result<SurfaceMesh>::failure(source + ":" + std::to_string(line_no) + ": normal coordinate '" +
                                            std::string(f[1 + k]) + "' is not a finite number");
    }
    normals.push_back(n);
  }
  if (normals.size() == s.positions.size()) s.normals = std::move(normals);
  return s;
}

Result<SurfaceMesh> decode_ply(std::string_view bytes, const std::string& source) {
  auto fail = [&](const std::string& why) { return Result<SurfaceMesh>::failure(source + ": " + why); };
  const std::string_view end_marker = "end_header\n";
  const size_t header_end = bytes.find(end_marker);
  if (bytes.substr(0, 4) != "ply\n" || header_end == std::string_view::npos)
    return fail("not a PLY file (no 'ply' line or no 'end_header')");
  std::string_view header = bytes.substr(0, header_end + end_marker.size());
  // Only the layout encode_ply writes is read: same lines in the same order, comments aside.
  std::string canonical;
  size_t vertex_count = 0, face_count = 0;
  LengthUnit unit = LengthUnit::Metre;
  size_t pos = 0;
  while (pos < header.size()) {
    const size_t end = header.find('\n', pos);
    std::string_view line = header.substr(pos, end - pos);
    pos = end + 1;
    if (line.starts_with("comment units ")) {
      auto named = named_unit(line, "comment units ", source);
      if (!named) return Result<SurfaceMesh>::failure(named.error());
      unit = *named;
    }
    if (line.starts_with("comment")) continue;
    auto f = split_fields(line);
    if (f.size() == 3 && f[0] == "element" && (f[1] == "vertex" || f[1] == "face")) {
      size_t count = 0;
      auto r = std::from_chars(f[2].data(), f[2].data() + f[2].size(), count);
      if (r.ec != std::errc() || r.ptr != f[2].data() + f[2].size())
        return fail("element count '" + std::string(f[2]) + "' is not a number");
      (f[1] == "vertex" ? vertex_count : face_count) = count;
      canonical += "element " + std::string(f[1]) + " N\n";
      continue;
    }
    canonical += std::string(line) + "\n";
  }
  const std::string expected = "ply\nformat binary_little_endian 1.0\nelement vertex N\n" +
                               std::string(kPlyVertexHeader) + "element face N\n" + std::string(kPlyFaceProperty) +
                               "end_header\n";
  if (canonical != expected)
    return fail("unsupported PLY layout (read: binary little-endian, vertex float x y z nx ny nz, face list uchar int)");
  if (vertex_count == 0) return fail("no vertices");
  if (face_count == 0) return fail("no faces");

  size_t at = header.size();
  const size_t vertex_bytes = 24;
  if ((bytes.size() - at) / vertex_bytes < vertex_count)
    return fail("truncated: " + std::to_string(vertex_count) + " vertices need " +
                std::to_string(vertex_count * vertex_bytes) + " bytes after the header");
  SurfaceMesh s;
  s.positions.resize(vertex_count);
  s.normals.resize(vertex_count);
  for (size_t v = 0; v < vertex_count; ++v, at += vertex_bytes) {
    s.positions[v] = get_vec3f(bytes, at);
    s.normals[v] = get_vec3f(bytes, at + 12);
    if (!is_finite(s.positions[v]) || !is_finite(s.normals[v]))
      return fail("vertex " + std::to_string(v) + " has a non-finite value");
  }
  // Each face takes at least its count byte and three indices: a larger count cannot be real, and
  // reserving for it could exhaust memory.
  if ((bytes.size() - at) / 13 < face_count)
    return fail("truncated: " + std::to_string(face_count) + " faces need at least 13 bytes each after the vertices");
  s.face_offsets.reserve(face_count + 1);
  for (size_t f = 0; f < face_count; ++f) {
    if (at >= bytes.size()) return fail("truncated in face " + std::to_string(f) + " of " + std::to_string(face_count));
    const uint8_t n = get<uint8_t>(bytes, at++);
    if (n < 3) return fail("face " + std::to_string(f) + " has " + std::to_string(n) + " vertices (fewer than 3)");
    if (bytes.size() - at < 4 * size_t{n})
      return fail("truncated in face " + std::to_string(f) + " of " + std::to_string(face_count));
    for (uint8_t k = 0; k < n; ++k, at += 4) {
      const int32_t index = get<int32_t>(bytes, at);
      if (index < 0 || static_cast<size_t>(index) >= vertex_count)
        return fail("face " + std::to_string(f) + " refers to vertex " + std::to_string(index) + " of " +
                    std::to_string(vertex_count));
      // The writer refuses such a face, so the reader does too.
      if (std::find(s.face_vertices.end() - k, s.face_vertices.end(), static_cast<uint32_t>(index)) != s.face_vertices.end())
        return fail("face " + std::to_string(f) + " uses vertex " + std::to_string(index) + " twice");
      s.face_vertices.push_back(static_cast<uint32_t>(index));
    }
    s.face_offsets.push_back(static_cast<uint32_t>(s.face_vertices.size()));
  }
  if (at != bytes.size()) return fail(std::to_string(bytes.size() - at) + " bytes after the last face");
  return in_metres(std::move(s), unit);
}

// ASCII STL: `solid NAME`, then per triangle `facet normal N N N`, `outer loop`, three `vertex X Y Z`, `endloop`,
// `endfacet`, and `endsolid`. Errors name the line.
Result<SurfaceMesh> decode_ascii_stl(std::string_view text, const std::string& source) {
  size_t at = 0, line = 1;
  std::string_view word;
  auto next = [&]() -> bool {
    while (at < text.size() && std::isspace(static_cast<unsigned char>(text[at]))) line += text[at++] == '\n';
    const size_t start = at;
    while (at < text.size() && !std::isspace(static_cast<unsigned char>(text[at]))) ++at;
    word = text.substr(start, at - start);
    return !word.empty();
  };
  auto fail = [&](const std::string& why) {
    return Result<SurfaceMesh>::failure(source + ":" + std::to_string(line) + ": ASCII STL: " + why);
  };
  auto expect = [&](std::string_view w) { return next() && word == w; };
  // STL holds floats: a number is kept as the float it becomes, and one beyond a float's range is refused.
  auto number = [&](double& v) {
    if (!next()) return false;
    const auto [end, ec] = std::from_chars(word.data(), word.data() + word.size(), v);
    if (ec != std::errc() || end != word.data() + word.size() || !(std::abs(v) <= std::numeric_limits<float>::max())) return false;
    v = static_cast<float>(v);
    return true;
  };
  auto vec = [&](Vec3& p) { return number(p.x()) && number(p.y()) && number(p.z()); };
  if (!expect("solid")) return fail("does not start with 'solid'");
  // The name runs to the end of the line.
  while (at < text.size() && text[at] != '\n') ++at;
  SurfaceMesh s;
  for (;;) {
    if (!next()) return fail("ends before 'endsolid'");
    if (word == "endsolid") break;
    if (word != "facet") return fail("expected 'facet' or 'endsolid', found '" + std::string(word.substr(0, 32)) + "'");
    Vec3 normal;
    if (!expect("normal") || !vec(normal)) return fail("expected 'normal' and three numbers a float holds");
    if (!expect("outer") || !expect("loop")) return fail("expected 'outer loop'");
    for (int k = 0; k < 3; ++k) {
      Vec3 p;
      if (!expect("vertex") || !vec(p)) return fail("expected 'vertex' and three numbers a float holds");
      s.face_vertices.push_back(static_cast<uint32_t>(s.positions.size()));
      s.positions.push_back(p);
      s.normals.push_back(normal);
    }
    if (!expect("endloop")) return fail("expected 'endloop' after three vertices (only triangles are STL facets)");
    if (!expect("endfacet")) return fail("expected 'endfacet'");
    s.face_offsets.push_back(static_cast<uint32_t>(s.face_vertices.size()));
  }
  if (s.face_offsets.size() < 2) return fail("no triangles");
  return s;
}

Result<SurfaceMesh> decode_stl(std::string_view bytes, const std::string& source) {
  auto fail = [&](const std::string& why) { return Result<SurfaceMesh>::failure(source + ": " + why); };
  // A binary file's 80-byte header may begin with "solid" too: its size decides.
  const bool binary_size = bytes.size() >= kStlHeaderBytes + 4 &&
                           bytes.size() == kStlHeaderBytes + 4 + kStlTriangleBytes * size_t{get<uint32_t>(bytes, kStlHeaderBytes)};
  const size_t first = bytes.find_first_not_of(" \t\r\n");
  if (!binary_size && first != std::string_view::npos && bytes.substr(first, 5) == "solid") return decode_ascii_stl(bytes.substr(first), source);
  if (bytes.size() < kStlHeaderBytes + 4) return fail("too short for a binary STL file (" + std::to_string(bytes.size()) + " bytes)");
  const uint32_t count = get<uint32_t>(bytes, kStlHeaderBytes);
  const size_t expected = kStlHeaderBytes + 4 + kStlTriangleBytes * size_t{count};
  if (bytes.size() != expected)
    return fail("binary STL with " + std::to_string(count) + " triangles must have " + std::to_string(expected) +
                " bytes, found " + std::to_string(bytes.size()));
  if (count == 0) return fail("no triangles");
  // Only FIRE's own header is read for a unit: other writers fill it with anything.
  auto unit = bytes.starts_with("FIRE ") ? named_unit(bytes.substr(0, kStlHeaderBytes), "units:", source)
                                         : Result<LengthUnit>(LengthUnit::Metre);
  if (!unit) return Result<SurfaceMesh>::failure(unit.error());
  SurfaceMesh s;
  s.positions.reserve(3 * size_t{count});
  s.normals.reserve(3 * size_t{count});
  s.face_offsets.reserve(size_t{count} + 1);
  for (uint32_t t = 0; t < count; ++t) {
    const size_t at = kStlHeaderBytes + 4 + kStlTriangleBytes * t;
    const Vec3 normal = get_vec3f(bytes, at);
    for (int k = 0; k < 3; ++k) {
      const Vec3 p = get_vec3f(bytes, at + 12 + 12 * k);
      if (!is_finite(p) || !is_finite(normal)) return fail("triangle " + std::to_string(t) + " has a non-finite value");
      s.face_vertices.push_back(static_cast<uint32_t>(s.positions.size()));
      s.positions.push_back(p);
      s.normals.push_back(normal);
    }
    s.face_offsets.push_back(static_cast<uint32_t>(s.face_vertices.size()));
  }
  return in_metres(std::move(s), *unit);
}

// A glTF count, offset or index must be a JSON integer from 0 up; nlohmann's get<uint64_t>() would wrap a
// negative one and is undefined for a fraction beyond the range, so the type is checked first.
struct GlbBad {
  std::string why;
};

uint64_t whole_number(const nlohmann::json& j, const std::string& what) {
  if (!j.is_number_unsigned()) throw GlbBad{what + " is not a whole number from 0 up"};
  return j.get<uint64_t>();
}

uint64_t whole_member(const nlohmann::json& object, const char* key, uint64_t fallback, const std::string& what) {
  return object.contains(key) ? whole_number(object.at(key), what + " " + key) : fallback;
}

struct GlbParts {
  GlbSummary summary;
  std::string_view bin;
  size_t position_offset = 0, normal_offset = 0, index_offset = 0;  // byte offsets into bin
  bool has_normals = false;
};

// The structural check, keeping where the data lives for decode_glb.
Result<GlbParts> parse_glb(std::string_view bytes, const std::string& source) {
  auto fail = [&](const std::string& why) { return Result<GlbParts>::failure(source + ": " + why); };
  GlbParts parts;
  GlbSummary& sum = parts.summary;
  if (bytes.size() < 12) return fail("too short for a glTF binary header (" + std::to_string(bytes.size()) + " bytes)");
  if (get<uint32_t>(bytes, 0) != kGlbMagic) return fail("not a glTF binary file (magic is not 'glTF')");
  if (const uint32_t version = get<uint32_t>(bytes, 4); version != 2)
    return fail("glTF binary version " + std::to_string(version) + ", expected 2");
  sum.total_length = get<uint32_t>(bytes, 8);
  if (sum.total_length != bytes.size())
    return fail("header length " + std::to_string(sum.total_length) + " differs from the file size " +
                std::to_string(bytes.size()));
  auto chunk = [&](size_t at, uint32_t type, const char* name, uint32_t& length) -> Status {
    if (bytes.size() - at < 8) return Status::failure(std::string("missing the ") + name + " chunk");
    length = get<uint32_t>(bytes, at);
    if (get<uint32_t>(bytes, at + 4) != type)
      return Status::failure(std::string("chunk at byte ") + std::to_string(at) + " is not the " + name + " chunk");
    if (length % 4 != 0) return Status::failure(std::string(name) + " chunk length " + std::to_string(length) + " is not a multiple of 4");
    if (bytes.size() - at - 8 < length)
      return Status::failure(std::string(name) + " chunk length " + std::to_string(length) + " runs past the end");
    return Status::success();
  };
  if (Status st = chunk(12, kGlbJsonChunk, "JSON", sum.json_length); !st) return fail(st.error);
  const size_t bin_at = 20 + size_t{sum.json_length};
  if (Status st = chunk(bin_at, kGlbBinChunk, "BIN", sum.bin_length); !st) return fail(st.error);
  if (bin_at + 8 + sum.bin_length != bytes.size())
    return fail(std::to_string(bytes.size() - bin_at - 8 - sum.bin_length) + " bytes after the BIN chunk");
  parts.bin = bytes.substr(bin_at + 8, sum.bin_length);

  using json = nlohmann::json;
  const json doc = json::parse(bytes.substr(20, sum.json_length), nullptr, /*allow_exceptions=*/false);
  if (doc.is_discarded() || !doc.is_object()) return fail("the JSON chunk is not a JSON object");
  try {
    if (doc.at("asset").at("version") != "2.0") return fail("asset.version is not \"2.0\"");
    const json& buffers = doc.at("buffers");
    if (buffers.size() != 1) return fail("expected one buffer, found " + std::to_string(buffers.size()));
    const uint64_t buffer_length = whole_number(buffers[0].at("byteLength"), "buffer byteLength");
    if (buffers[0].contains("uri")) return fail("the buffer has a uri; a .glb buffer lives in the BIN chunk");
    // The BIN chunk may pad the buffer by up to 3 bytes.
    if (buffer_length > sum.bin_length || sum.bin_length - buffer_length > 3)
      return fail("buffer byteLength " + std::to_string(buffer_length) + " does not match the BIN chunk (" +
                  std::to_string(sum.bin_length) + " bytes)");
    const json& views = doc.at("bufferViews");
    for (size_t i = 0; i < views.size(); ++i) {
      const std::string view_name = "bufferView " + std::to_string(i);
      const uint64_t offset = whole_member(views[i], "byteOffset", 0, view_name);
      const uint64_t length = whole_number(views[i].at("byteLength"), view_name + " byteLength");
      // Compared without adding, so that offsets near 2^64 cannot wrap around past the check.
      if (views[i].at("buffer") != 0 || length > buffer_length || offset > buffer_length - length)
        return fail("bufferView " + std::to_string(i) + " (offset " + std::to_string(offset) + ", length " +
                    std::to_string(length) + ") does not fit the buffer of " + std::to_string(buffer_length) + " bytes");
    }
    const json& accessors = doc.at("accessors");
    const json& primitive = doc.at("meshes").at(0).at("primitives").at(0);
    if (primitive.contains("mode") && primitive.at("mode") != 4) return fail("the primitive is not a triangle list");
    // Checks accessor `index` has the expected type and fits its bufferView; returns its byte offset in bin.
    auto accessor = [&](const json& ref, const char* role, int component_type, const char* type, size_t components,
                        uint64_t& count, size_t& bin_offset) -> Status {
      const uint64_t index = whole_number(ref, std::string(role) + " accessor index");
      if (index >= accessors.size()) return Status::failure(std::string(role) + " accessor " + std::to_string(index) + " does not exist");
      const json& a = accessors[index];
      if (a.at("componentType") != component_type || a.at("type") != type)
        return Status::failure(std::string(role) + " accessor is not " + type + " of component type " + std::to_string(component_type));
      const uint64_t view_index = whole_number(a.at("bufferView"), std::string(role) + " accessor's bufferView");
      if (view_index >= views.size()) return Status::failure(std::string(role) + " accessor's bufferView does not exist");
      const json& view = views[view_index];
      count = whole_number(a.at("count"), std::string(role) + " accessor's count");
      const uint64_t element = 4 * components;
      const uint64_t stride = whole_member(view, "byteStride", element, std::string(role) + " bufferView");
      if (stride != element) return Status::failure(std::string(role) + " data is interleaved (byteStride " + std::to_string(stride) + ")");
      const uint64_t offset = whole_member(a, "byteOffset", 0, std::string(role) + " accessor");
      // The bufferView lies inside the buffer (checked above), so its length and offset are below 2^32 and
      // these comparisons, made without multiplying the count, cannot wrap around.
      const uint64_t view_length = view.at("byteLength").get<uint64_t>();
      if (offset > view_length || (view_length - offset) / element < count)
        return Status::failure(std::string(role) + " accessor needs " + std::to_string(count) + " elements of " +
                               std::to_string(element) + " bytes from byte " + std::to_string(offset) +
                               ", its bufferView has " + std::to_string(view_length));
      bin_offset = view.value("byteOffset", uint64_t{0}) + offset;
      if (bin_offset % 4 != 0) return Status::failure(std::string(role) + " data is not 4-byte aligned");
      return Status::success();
    };
    const json& attributes = primitive.at("attributes");
    uint64_t vertex_count = 0, normal_count = 0, index_count = 0;
    if (Status st = accessor(attributes.at("POSITION"), "POSITION", kGlFloat, "VEC3", 3, vertex_count, parts.position_offset); !st)
      return fail(st.error);
    if (attributes.contains("NORMAL")) {
      if (Status st = accessor(attributes.at("NORMAL"), "NORMAL", kGlFloat, "VEC3", 3, normal_count, parts.normal_offset); !st)
        return fail(st.error);
      if (normal_count != vertex_count) return fail("NORMAL count differs from POSITION count");
      parts.has_normals = true;
    }
    if (Status st = accessor(primitive.at("indices"), "indices", kGlUnsignedInt, "SCALAR", 1, index_count, parts.index_offset); !st)
      return fail(st.error);
    if (vertex_count == 0 || index_count == 0 || index_count % 3 != 0)
      return fail(std::to_string(vertex_count) + " vertices and " + std::to_string(index_count) +
                  " indices do not make a triangle mesh");
    if (vertex_count > std::numeric_limits<uint32_t>::max() || index_count > std::numeric_limits<uint32_t>::max())
      return fail("counts exceed 32 bits");
    sum.vertex_count = static_cast<uint32_t>(vertex_count);
    sum.index_count = static_cast<uint32_t>(index_count);
    const json& position = accessors[attributes.at("POSITION").get<uint64_t>()];
    if (!position.contains("min") || !position.contains("max")) return fail("POSITION accessor lacks min/max (required)");
    Eigen::Vector3f lo = Eigen::Vector3f::Constant(std::numeric_limits<float>::max()), hi = -lo;
    for (uint32_t v = 0; v < sum.vertex_count; ++v) {
      const Vec3 p = get_vec3f(parts.bin, parts.position_offset + 12 * size_t{v});
      if (!is_finite(p)) return fail("POSITION " + std::to_string(v) + " is not finite");
      lo = lo.cwiseMin(p.cast<float>());
      hi = hi.cwiseMax(p.cast<float>());
    }
    for (int k = 0; k < 3; ++k) {
      sum.position_min[k] = position.at("min").at(k).get<double>();
      sum.position_max[k] = position.at("max").at(k).get<double>();
      if (static_cast<float>(sum.position_min[k]) != lo[k] || static_cast<float>(sum.position_max[k]) != hi[k])
        return fail("POSITION min/max do not match the data");
    }
    for (uint32_t i = 0; i < sum.index_count; ++i)
      if (get<uint32_t>(parts.bin, parts.index_offset + 4 * size_t{i}) >= sum.vertex_count)
        return fail("index " + std::to_string(i) + " is not below the vertex count " + std::to_string(sum.vertex_count));
  } catch (const GlbBad& bad) {
    return fail(bad.why);
  } catch (const nlohmann::json::exception& e) {
    // A missing member or a wrong type anywhere in the JSON chunk (outside the frame loop: a file boundary).
    return fail(std::string("malformed glTF JSON: ") + e.what());
  }
  return parts;
}

Result<SurfaceMesh> decode_glb(std::string_view bytes, const std::string& source) {
  auto parsed = parse_glb(bytes, source);
  if (!parsed) return Result<SurfaceMesh>::failure(parsed.error());
  const GlbParts& parts = *parsed;
  SurfaceMesh s;
  s.positions.resize(parts.summary.vertex_count);
  for (uint32_t v = 0; v < parts.summary.vertex_count; ++v)
    s.positions[v] = from_gltf(get_vec3f(parts.bin, parts.position_offset + 12 * size_t{v}));
  if (parts.has_normals) {
    s.normals.resize(parts.summary.vertex_count);
    for (uint32_t v = 0; v < parts.summary.vertex_count; ++v) {
      s.normals[v] = from_gltf(get_vec3f(parts.bin, parts.normal_offset + 12 * size_t{v}));
      if (!is_finite(s.normals[v])) return Result<SurfaceMesh>::failure(source + ": NORMAL " + std::to_string(v) + " is not finite");
    }
  }
  s.face_vertices.resize(parts.summary.index_count);
  for (uint32_t i = 0; i < parts.summary.index_count; ++i)
    s.face_vertices[i] = get<uint32_t>(parts.bin, parts.index_offset + 4 * size_t{i});
  for (uint32_t t = 0; t < parts.summary.index_count / 3; ++t) {
    const uint32_t* tri = s.face_vertices.data() + 3 * size_t{t};
    // A degenerate triangle is valid glTF, but not a surface the writer accepts or `fire eval` measures.
    if (tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2])
      return Result<SurfaceMesh>::failure(source + ": triangle " + std::to_string(t) + " (indices " +
                                          std::to_string(tri[0]) + ", " + std::to_string(tri[1]) + ", " +
                                          std::to_string(tri[2]) + ") repeats a vertex");
    s.face_offsets.push_back(3 * (t + 1));
  }
  return s;
}

}  // namespace

double units_per_metre(LengthUnit unit) {
  switch (unit) {
    case LengthUnit::Millimetre: return 1000;
    case LengthUnit::Centimetre: return 100;
    case LengthUnit::Metre: return 1;
  }
  return 1;
}

const char* unit_name(LengthUnit unit) {
  switch (unit) {
    case LengthUnit::Millimetre: return "mm";
    case LengthUnit::Centimetre: return "cm";
    case LengthUnit::Metre: return "m";
  }
  return "m";
}

Result<LengthUnit> length_unit_of(std::string_view name) {
  for (LengthUnit u : {LengthUnit::Millimetre, LengthUnit::Centimetre, LengthUnit::Metre})
    if (name == unit_name(u)) return u;
  return Result<LengthUnit>::failure("unknown length unit '" + std::string(name.substr(0, 32)) + "' (mm, cm or m)");
}

Result<SurfaceFormat> surface_format_of(const std::string& path) {
  const std::string ext = file_extension(path);
  if (ext == "obj") return SurfaceFormat::Obj;
  if (ext == "ply") return SurfaceFormat::Ply;
  if (ext == "stl") return SurfaceFormat::Stl;
  if (ext == "glb") return SurfaceFormat::Glb;
  return Result<SurfaceFormat>::failure(path + ": unknown surface format '" + ext +
                                        "' (the extension must be .obj, .ply, .stl or .glb)");
}

Result<std::string> encode_surface(const SurfaceMesh& metres, SurfaceFormat format, const std::string& source,
                                   LengthUnit unit) {
  if (format == SurfaceFormat::Glb) unit = LengthUnit::Metre;
  SurfaceMesh scaled;
  if (unit != LengthUnit::Metre) {
    scaled = metres;
    for (Vec3& p : scaled.positions) p *= units_per_metre(unit);
  }
  const SurfaceMesh& surface = unit == LengthUnit::Metre ? metres : scaled;
  if (Status st = check_surface(surface, format != SurfaceFormat::Obj); !st)
    return Result<std::string>::failure(source + ": cannot export" + (unit == LengthUnit::Metre ? "" : std::string(" in ") + unit_name(unit)) +
                                        ": " + st.error);
  const std::vector<Vec3> normals = export_normals(surface);
  Result<std::string> bytes = std::string();
  switch (format) {
    case SurfaceFormat::Obj: bytes = encode_obj(surface, normals, unit); break;
    case SurfaceFormat::Ply: bytes = encode_ply(surface, normals, unit); break;
    case SurfaceFormat::Stl: bytes = encode_stl(surface, unit); break;
    case SurfaceFormat::Glb: bytes = encode_glb(surface, normals); break;
  }
  if (!bytes) return Result<std::string>::failure(source + ": cannot export: " + bytes.error());
  return bytes;
}

Status write_surface(const SurfaceMesh& surface, const std::string& path, LengthUnit unit) {
  auto format = surface_format_of(path);
  if (!format) return Status::failure(format.error());
  auto bytes = encode_surface(surface, *format, path, unit);
  if (!bytes) return Status::failure(bytes.error());
  return write_file_atomic(path, *bytes);
}

Result<SurfaceMesh> decode_surface(std::string_view bytes, SurfaceFormat format, const std::string& source) {
  switch (format) {
    case SurfaceFormat::Obj: return decode_obj(bytes, source);
    case SurfaceFormat::Ply: return decode_ply(bytes, source);
    case SurfaceFormat::Stl: return decode_stl(bytes, source);
    case SurfaceFormat::Glb: return decode_glb(bytes, source);
  }
  return Result<SurfaceMesh>::failure(source + ": unknown surface format");
}

Result<SurfaceMesh> read_surface(const std::string& path) {
  auto format = surface_format_of(path);
  if (!format) return Result<SurfaceMesh>::failure(format.error());
  auto bytes = read_text_file(path);
  if (!bytes) return Result<SurfaceMesh>::failure(bytes.error());
  return decode_surface(*bytes, *format, path);
}

Result<GlbSummary> check_glb(std::string_view bytes, const std::string& source) {
  auto parts = parse_glb(bytes, source);
  if (!parts) return Result<GlbSummary>::failure(parts.error());
  return parts->summary;
}

}  // namespace fire
