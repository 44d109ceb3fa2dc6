#include "platform/obj.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <map>

#include "engine/text.hpp"
#include "platform/files.hpp"
#include "platform/surface_io.hpp"

namespace fire {


Result<PolygonMesh> parse_obj(std::string_view text, const std::string& source) {
  PolygonMesh mesh;
  auto fail = [&](size_t line, const std::string& why) {
    return Result<PolygonMesh>::failure(source + ":" + std::to_string(line) + ": " + why);
  };
  LengthUnit unit = LengthUnit::Metre;
  size_t pos = 0, line_no = 0;
  while (pos < text.size()) {
    size_t end = text.find('\n', pos);
    if (end == std::string_view::npos) end = text.size();
    std::string_view line = text.substr(pos, end - pos);
    pos = end + 1;
    ++line_no;
    auto f = split_fields(line);
    if (f.size() >= 3 && f[0] == "#" && f[1] == "units:") {
      const std::string_view word = f[2].substr(0, f[2].find(','));
      auto named = length_unit_of(word);
      if (!named) return fail(line_no, named.error());
      unit = *named;
      continue;
    }
    if (f.empty() || f[0][0] == '#') continue;
    if (f[0] == "v") {
      if (f.size() < 4) return fail(line_no, "vertex needs three coordinates");
      Vec3 p;
      for (int k = 0; k < 3; ++k) {
        auto r = std::from_chars(f[1 + k].data(), f[1 + k].data() + f[1 + k].size(), p[k]);
        if (r.ec != std::errc() || r.ptr != f[1 + k].data() + f[1 + k].size())
          return fail(line_no, "vertex coordinate '" + std::string(f[1 + k]) + "' is not a number");
      }
      if (!is_finite(p)) return fail(line_no, "vertex coordinate is not finite (NaN or infinity)");
      mesh.positions.push_back(p);
    } else if (f[0] == "f") {
      if (f.size() < 4) return fail(line_no, "face needs at least 3 vertices");
      size_t first = mesh.face_vertices.size();
      for (size_t k = 1; k < f.size(); ++k) {
        std::string_view tok = f[k].substr(0, f[k].find('/'));
        long long idx = 0;
        auto r = std::from_chars(tok.data(), tok.data() + tok.size(), idx);
        if (tok.empty() || r.ec != std::errc() || r.ptr != tok.data() + tok.size() || idx == 0)
          return fail(line_no, "face vertex '" + std::string(f[k]) + "' is not a vertex index");
        long long n = static_cast<long long>(mesh.positions.size());
        long long zero_based = idx > 0 ? idx - 1 : n + idx;
        if (zero_based < 0 || zero_based >= n)
          return fail(line_no, "face vertex index " + std::to_string(idx) + " is out of range (" + std::to_string(n) + " vertices so far)");
        for (size_t q = first; q < mesh.face_vertices.size(); ++q)
          if (mesh.face_vertices[q] == static_cast<uint32_t>(zero_based))
            return fail(line_no, "face uses vertex " + std::to_string(zero_based + 1) + " twice");
        mesh.face_vertices.push_back(static_cast<uint32_t>(zero_based));
      }
      mesh.face_offsets.push_back(static_cast<uint32_t>(mesh.face_vertices.size()));
    }
  }
  if (mesh.positions.empty()) return Result<PolygonMesh>::failure(source + ": no vertices (empty or not an OBJ file)");
  if (mesh.face_count() == 0) return Result<PolygonMesh>::failure(source + ": no faces");
  if (unit != LengthUnit::Metre)
    for (Vec3& p : mesh.positions) p /= units_per_metre(unit);
  return mesh;
}

Result<PolygonMesh> read_obj(const std::string& path) {
  auto text = read_text_file(path);
  if (!text) return Result<PolygonMesh>::failure(text.error());
  return parse_obj(*text, path);
}

std::vector<uint8_t> border_vertices(const PolygonMesh& mesh) {
  std::map<std::pair<uint32_t, uint32_t>, uint32_t> uses;
  for (size_t f = 0; f < mesh.face_count(); ++f) {
    const auto face = mesh.face(f);
    for (size_t k = 0; k < face.size(); ++k) {
      const uint32_t a = face[k], b = face[(k + 1) % face.size()];
      ++uses[{std::min(a, b), std::max(a, b)}];
    }
  }
  std::vector<uint8_t> border(mesh.positions.size(), 0);
  for (const auto& [edge, count] : uses)
    if (count == 1) border[edge.first] = border[edge.second] = 1;
  return border;
}

Result<SubdivisionTags> parse_obj_tags(std::string_view text, const std::string& source, const PolygonMesh& mesh) {
  using R = Result<SubdivisionTags>;
  auto fail = [&](size_t line, const std::string& why) { return R::failure(source + ":" + std::to_string(line) + ": " + why); };
  const size_t n = mesh.positions.size();
  std::vector<uint32_t> creases;
  std::vector<std::pair<size_t, uint32_t>> corners;  // (line, vertex)
  int boundary = 1;
  size_t pos = 0, line_no = 0;
  while (pos < text.size()) {
    size_t end = text.find('\n', pos);
    if (end == std::string_view::npos) end = text.size();
    const std::vector<std::string_view> f = split_fields(text.substr(pos, end - pos));
    pos = end + 1;
    ++line_no;
    if (f.empty() || f[0] != "t") continue;
    auto number = [&](size_t k, double& value) {
      const auto [ptr, ec] = std::from_chars(f[k].data(), f[k].data() + f[k].size(), value);
      return ec == std::errc() && ptr == f[k].data() + f[k].size() && std::isfinite(value);
    };
    auto vertex = [&](size_t k, uint32_t& v) {
      double x = 0;
      if (!number(k, x) || x < 0 || x >= double(n) || x != std::floor(x)) return false;
      v = uint32_t(x);
      return true;
    };
    const std::string name = f.size() > 1 ? std::string(f[1]) : "";
    if (name == "crease" && f.size() == 6 && f[2] == "2/1/0") {
      uint32_t a = 0, b = 0;
      double sharpness = 0;
      if (!vertex(3, a) || !vertex(4, b)) return fail(line_no, "crease: vertex indices (from 0) of " + std::to_string(n) + " vertices expected");
      if (!number(5, sharpness) || sharpness < 10)
        return fail(line_no, "crease sharpness " + std::string(f[5]) + ": FIRE's subdivision takes only infinitely sharp creases (10 or more)");
      creases.insert(creases.end(), {a, b});
    } else if (name == "corner" && f.size() == 5 && f[2] == "1/1/0") {
      uint32_t v = 0;
      double sharpness = 0;
      if (!vertex(3, v)) return fail(line_no, "corner: a vertex index (from 0) of " + std::to_string(n) + " vertices expected");
      if (!number(4, sharpness) || sharpness < 10)
        return fail(line_no, "corner sharpness " + std::string(f[4]) + ": FIRE's subdivision takes only infinitely sharp corners (10 or more)");
      corners.push_back({line_no, v});
    } else if (name == "interpolateboundary" && f.size() == 4 && f[2] == "1/0/0" && (f[3] == "1" || f[3] == "2")) {
      boundary = f[3] == "1" ? 1 : 2;
    } else {
      return fail(line_no, "tag '" + name +
                               "' is not one FIRE's subdivision honours (t crease 2/1/0 A B S, t corner 1/1/0 V S, "
                               "t interpolateboundary 1/0/0 1 or 2)");
    }
  }
  SubdivisionTags tags;
  tags.sharp_edges = std::move(creases);
  if (boundary == 1 && corners.empty()) return tags;
  // Border vertices, and those of one face (EdgeAndCorner's corners).
  std::vector<uint32_t> faces_at(n, 0);
  for (uint32_t v : mesh.face_vertices) ++faces_at[v];
  const std::vector<uint8_t> border = border_vertices(mesh);
  tags.border_corners.assign(n, 0);
  if (boundary == 1)
    for (uint32_t v = 0; v < n; ++v) tags.border_corners[v] = border[v] && faces_at[v] == 1;
  for (const auto& [line, v] : corners) {
    if (!border[v]) return fail(line, "corner at vertex " + std::to_string(v) + ", which is not on the border: FIRE's subdivision makes corners of border vertices only");
    tags.border_corners[v] = 1;
  }
  return tags;
}

}  // namespace fire
