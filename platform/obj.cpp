#include "platform/obj.hpp"

#include <charconv>

#include "engine/text.hpp"
#include "platform/files.hpp"
#include "platform/surface_io.hpp"

namespace fire {


Result<PolygonMesh> parse_obj(std::string_view text, const std::string& source) {
  PolygonMesh mesh;
  auto fail = [&](size_t line, const std::string& why) {
    return Result<PolygonMesh>::failure(source + ":" + std::to_string(line) + ": " + why);
  };
  LengthUnit unit = LengthUnit::m;
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
  if (unit != LengthUnit::m)
    for (Vec3& p : mesh.positions) p /= units_per_metre(unit);
  return mesh;
}

Result<PolygonMesh> read_obj(const std::string& path) {
  auto text = read_text_file(path);
  if (!text) return Result<PolygonMesh>::failure(text.error());
  return parse_obj(*text, path);
}

}  // namespace fire
