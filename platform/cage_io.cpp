#include "platform/cage_io.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <utility>
#include <vector>

#include "platform/files.hpp"
#include "platform/obj.hpp"

namespace fire {

namespace {

void append_number(std::string& out, double value) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, value);
  out.append(buf, r.ptr);
}

// The border vertices FIRE's rule makes corners (flags of inner vertices mean nothing to it).
std::vector<uint32_t> corner_vertices(const Cage& cage) {
  std::vector<uint32_t> corners;
  if (cage.border_corners.empty()) return corners;
  const std::vector<uint8_t> border = border_vertices(cage.mesh);
  for (uint32_t v = 0; v < cage.border_corners.size(); ++v)
    if (cage.border_corners[v] && border[v]) corners.push_back(v);
  return corners;
}

Status check_cage(const Cage& cage) {
  const size_t n = cage.mesh.positions.size();
  if (n == 0 || cage.mesh.face_count() == 0) return Status::failure("the cage has no faces");
  for (const Vec3& p : cage.mesh.positions)
    if (!is_finite(p)) return Status::failure("the cage has a non-finite point");
  for (uint32_t v : cage.mesh.face_vertices)
    if (v >= n) return Status::failure("a face of the cage refers to vertex " + std::to_string(v) + " of " + std::to_string(n));
  if (cage.sharp_edges.size() % 2 != 0) return Status::failure("the cage's sharp edges are not pairs");
  for (uint32_t v : cage.sharp_edges)
    if (v >= n) return Status::failure("a sharp edge of the cage refers to vertex " + std::to_string(v) + " of " + std::to_string(n));
  if (!cage.border_corners.empty() && cage.border_corners.size() != n)
    return Status::failure("the cage's border corners are not one per vertex");
  return Status::success();
}

}  // namespace

Status check_cage_path(const std::string& path) {
  const std::string ext = file_extension(path);
  if (ext == "obj" || ext == "usda") return Status::success();
  return Status::failure(path + ": unknown cage format '" + ext + "' (the extension must be .obj or .usda)");
}

Result<std::string> encode_cage_obj(const Cage& cage, LengthUnit unit, std::string_view title) {
  if (Status s = check_cage(cage); !s) return Result<std::string>::failure(s.error);
  const double scale = units_per_metre(unit);
  std::string out = title.empty() ? std::string() : "# " + std::string(title) + "\n";
  out += "# FIRE subdivision cage: Catmull-Clark, " + std::to_string(cage.mesh.positions.size()) + " vertices, " +
                    std::to_string(cage.mesh.face_count()) + " faces; OpenSubdiv's tags below (vertex indices from 0)\n" +
                    "# units: " + unit_name(unit) + ", up: +Z\n";
  for (const Vec3& p : cage.mesh.positions) {
    out += 'v';
    for (int k = 0; k < 3; ++k) {
      out += ' ';
      append_number(out, p[k] * scale);
    }
    out += '\n';
  }
  for (size_t f = 0; f < cage.mesh.face_count(); ++f) {
    out += 'f';
    for (uint32_t v : cage.mesh.face(f)) out += ' ' + std::to_string(v + 1);
    out += '\n';
  }
  // OpenSubdiv's shapes: 1 is EdgeAndCorner, 2 EdgeOnly (RenderMan's interpolateboundary values).
  out += cage.border_corners.empty() ? "t interpolateboundary 1/0/0 1\n" : "t interpolateboundary 1/0/0 2\n";
  for (size_t i = 0; i + 1 < cage.sharp_edges.size(); i += 2)
    out += "t crease 2/1/0 " + std::to_string(cage.sharp_edges[i]) + ' ' + std::to_string(cage.sharp_edges[i + 1]) + " 10\n";
  for (uint32_t v : corner_vertices(cage)) out += "t corner 1/1/0 " + std::to_string(v) + " 10\n";
  return out;
}

Result<std::string> encode_cage_usda(const Cage& cage, LengthUnit unit) {
  if (Status s = check_cage(cage); !s) return Result<std::string>::failure(s.error);
  const double scale = units_per_metre(unit);
  std::string out = "#usda 1.0\n(\n    defaultPrim = \"cage\"\n    doc = \"FIRE subdivision cage\"\n    metersPerUnit = ";
  append_number(out, 1 / units_per_metre(unit));
  out += "\n    upAxis = \"Z\"\n)\n\ndef Mesh \"cage\"\n{\n";
  out += "    uniform token subdivisionScheme = \"catmullClark\"\n";
  out += std::string("    uniform token interpolateBoundary = \"") + (cage.border_corners.empty() ? "edgeAndCorner" : "edgeOnly") + "\"\n";
  out += "    uniform token orientation = \"rightHanded\"\n";
  auto int_array = [&](const char* name, auto begin, auto end, auto value) {
    out += std::string("    int[] ") + name + " = [";
    for (auto it = begin; it != end; ++it) {
      if (it != begin) out += ", ";
      out += std::to_string(value(it));
    }
    out += "]\n";
  };
  std::vector<uint32_t> counts(cage.mesh.face_count());
  for (size_t f = 0; f < counts.size(); ++f) counts[f] = cage.mesh.face_size(f);
  int_array("faceVertexCounts", counts.begin(), counts.end(), [](auto it) { return *it; });
  int_array("faceVertexIndices", cage.mesh.face_vertices.begin(), cage.mesh.face_vertices.end(), [](auto it) { return *it; });
  out += "    point3f[] points = [";
  for (size_t v = 0; v < cage.mesh.positions.size(); ++v) {
    out += v ? ", (" : "(";
    for (int k = 0; k < 3; ++k) {
      if (k) out += ", ";
      append_number(out, static_cast<float>(cage.mesh.positions[v][k] * scale));
    }
    out += ')';
  }
  out += "]\n";
  auto float_array = [&](const char* name, size_t count) {
    out += std::string("    float[] ") + name + " = [";
    for (size_t i = 0; i < count; ++i) out += i ? ", 10" : "10";
    out += "]\n";
  };
  const size_t creases = cage.sharp_edges.size() / 2;
  if (creases > 0) {
    int_array("creaseIndices", cage.sharp_edges.begin(), cage.sharp_edges.end(), [](auto it) { return *it; });
    const std::vector<uint32_t> lengths(creases, 2);
    int_array("creaseLengths", lengths.begin(), lengths.end(), [](auto it) { return *it; });
    float_array("creaseSharpnesses", creases);
  }
  const std::vector<uint32_t> corners = corner_vertices(cage);
  if (!corners.empty()) {
    int_array("cornerIndices", corners.begin(), corners.end(), [](auto it) { return *it; });
    float_array("cornerSharpnesses", corners.size());
  }
  out += "}\n";
  return out;
}

Status write_cage(const Cage& cage, const std::string& path, LengthUnit unit) {
  if (Status s = check_cage_path(path); !s) return s;
  Result<std::string> text = file_extension(path) == "usda" ? encode_cage_usda(cage, unit) : encode_cage_obj(cage, unit);
  if (!text) return Status::failure(path + ": cannot export the cage: " + text.error());
  return write_file_atomic(path, *text);
}

namespace {

// The value text after `name =` (to the end of its line, or its [...] list), or nothing.
std::string_view value_of(std::string_view text, std::string_view name) {
  size_t at = 0;
  while ((at = text.find(name, at)) != std::string_view::npos) {
    const bool starts_word = at == 0 || !(std::isalnum(static_cast<unsigned char>(text[at - 1])) || text[at - 1] == '_');
    size_t i = at + name.size();
    while (i < text.size() && text[i] == ' ') ++i;
    if (starts_word && i < text.size() && text[i] == '=') {
      ++i;
      while (i < text.size() && text[i] == ' ') ++i;
      const size_t end = i < text.size() && text[i] == '[' ? text.find(']', i) : text.find('\n', i);
      if (end == std::string_view::npos) return text.substr(i);
      return text.substr(i, end - i + (text[i] == '['));
    }
    at = i;
  }
  return {};
}

// The numbers of a list value ("[1, 2, 3]" or "[(1, 2, 3), ...]"), in order.
Result<std::vector<double>> numbers_of(std::string_view list, const std::string& what) {
  std::vector<double> out;
  if (list.size() < 2 || list.front() != '[' || list.back() != ']')
    return Result<std::vector<double>>::failure(what + " is not a list in [ ]");
  size_t i = 1;
  while (i + 1 < list.size()) {
    const char c = list[i];
    if (c == ' ' || c == ',' || c == '(' || c == ')' || c == '\n') {
      ++i;
      continue;
    }
    double v = 0;
    const auto [end, ec] = std::from_chars(list.data() + i, list.data() + list.size() - 1, v);
    if (ec != std::errc() || !std::isfinite(v))
      return Result<std::vector<double>>::failure(what + ": '" + std::string(list.substr(i, 16)) + "' is not a finite number");
    out.push_back(v);
    i = static_cast<size_t>(end - list.data());
  }
  return out;
}

}  // namespace

Result<Cage> decode_cage_usda(std::string_view text, const std::string& source) {
  using R = Result<Cage>;
  auto fail = [&](const std::string& why) { return R::failure(source + ": " + why); };
  if (!text.starts_with("#usda 1.0")) return fail("not a USDA file (no '#usda 1.0' line)");
  if (value_of(text, "subdivisionScheme") != "\"catmullClark\"") return fail("the mesh is not subdivisionScheme \"catmullClark\"");
  const std::string_view boundary = value_of(text, "interpolateBoundary");
  if (boundary != "\"edgeOnly\"" && boundary != "\"edgeAndCorner\"")
    return fail("interpolateBoundary must be \"edgeOnly\" or \"edgeAndCorner\"");
  double metres = 1;
  if (const std::string_view m = value_of(text, "metersPerUnit"); !m.empty()) {
    const auto [end, ec] = std::from_chars(m.data(), m.data() + m.size(), metres);
    if (ec != std::errc() || !(metres > 0) || !std::isfinite(metres)) return fail("metersPerUnit is not a positive number");
  }
  // Points are divided by the units in a metre, exact for ours (1000, 100, 1), as surface_io.cpp's readers do.
  const double per_metre = 1 / metres;
  const double units = std::abs(per_metre - std::round(per_metre)) < 1e-9 * per_metre ? std::round(per_metre) : per_metre;
  auto list = [&](const char* name, bool required) -> Result<std::vector<double>> {
    const std::string_view value = value_of(text, name);
    if (value.empty()) {
      if (required) return Result<std::vector<double>>::failure(source + ": no " + name);
      return std::vector<double>{};
    }
    auto numbers = numbers_of(value, name);
    if (!numbers) return Result<std::vector<double>>::failure(source + ": " + numbers.error());
    return numbers;
  };
  auto counts = list("faceVertexCounts", true);
  if (!counts) return R::failure(counts.error());
  auto indices = list("faceVertexIndices", true);
  if (!indices) return R::failure(indices.error());
  auto points = list("points", true);
  if (!points) return R::failure(points.error());
  auto creases = list("creaseIndices", false);
  if (!creases) return R::failure(creases.error());
  auto lengths = list("creaseLengths", false);
  if (!lengths) return R::failure(lengths.error());
  auto corners = list("cornerIndices", false);
  if (!corners) return R::failure(corners.error());
  if (points->size() % 3 != 0) return fail("points are not triples");
  Cage cage;
  const size_t n = points->size() / 3;
  for (size_t v = 0; v < n; ++v) cage.mesh.positions.push_back(Vec3((*points)[3 * v], (*points)[3 * v + 1], (*points)[3 * v + 2]) / units);
  auto index = [&](double x) { return x >= 0 && x < double(n) && x == std::floor(x); };
  size_t at = 0;
  for (double c : *counts) {
    if (!(c >= 3) || c != std::floor(c) || at + size_t(c) > indices->size()) return fail("faceVertexCounts do not match faceVertexIndices");
    for (size_t k = 0; k < size_t(c); ++k, ++at) {
      if (!index((*indices)[at])) return fail("faceVertexIndices refer to a point that is not there");
      cage.mesh.face_vertices.push_back(uint32_t((*indices)[at]));
    }
    cage.mesh.face_offsets.push_back(uint32_t(at));
  }
  if (at != indices->size()) return fail("faceVertexCounts do not match faceVertexIndices");
  for (double l : *lengths)
    if (l != 2) return fail("only creases of one edge (creaseLengths 2), as FIRE writes them, are read");
  if (creases->size() != 2 * lengths->size()) return fail("creaseIndices do not match creaseLengths");
  for (double v : *creases) {
    if (!index(v)) return fail("creaseIndices refer to a point that is not there");
    cage.sharp_edges.push_back(uint32_t(v));
  }
  if (boundary == "\"edgeOnly\"") {
    cage.border_corners.assign(n, 0);
    for (double v : *corners) {
      if (!index(v)) return fail("cornerIndices refer to a point that is not there");
      cage.border_corners[size_t(v)] = 1;
    }
  } else if (!corners->empty()) return fail("cornerIndices with edgeAndCorner are not what FIRE writes");
  return cage;
}

}  // namespace fire
