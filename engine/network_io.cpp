#include "engine/network_io.hpp"

#include <nlohmann/json.hpp>

#include "engine/input_log.hpp"

namespace fire {

using nlohmann::json;

std::string network_to_json(const Mesh& m) {
  json vertices = json::array(), edges = json::array(), faces = json::array();
  auto point = [](const Vec3& p) { return json::array({p.x(), p.y(), p.z()}); };
  for (VertexIndex v{0}; v < m.vertex_slots(); ++v)
    vertices.push_back({{"p", point(m.vertices.position[v])}, {"split", bool(m.vertices.flags[v] & kSplitVertex)}});
  for (EdgeIndex e{0}; e < m.edge_slots(); ++e) {
    json pts = json::array();
    for (const Vec3& p : m.polyline(e)) pts.push_back(point(p));
    edges.push_back({{"v", {m.edges.vertex[e][0], m.edges.vertex[e][1]}},
                     {"sharp", bool(m.edges.flags[e] & kSharpEdge)},
                     {"points", std::move(pts)}});
    if (m.edges.flags[e] & kBridgeEdge) edges.back()["bridge"] = true;  // only then: older networks read the same
    if (m.edges.flags[e] & kPendingEdge) edges.back()["pending"] = true;
  }
  for (FaceIndex f{0}; f < m.face_slots(); ++f) {
    json es = json::array(), rs = json::array();
    for (OrientedEdge oe : m.face_loop(f)) {
      es.push_back(edge_of(oe).value);
      rs.push_back(is_reversed(oe));
    }
    faces.push_back({{"edges", std::move(es)}, {"reversed", std::move(rs)}});
  }
  json doc = {{"format", "fire-network"}, {"version", 1}, {"vertices", std::move(vertices)},
              {"edges", std::move(edges)}, {"faces", std::move(faces)}};
  return doc.dump() + "\n";
}

namespace {

struct Bad {
  std::string why;
};

const json& field(const json& j, const char* key, const std::string& where) {
  if (!j.is_object() || !j.contains(key)) throw Bad{where + " has no \"" + key + "\""};
  return j.at(key);
}

Vec3 read_point(const json& j, const std::string& where) {
  if (!j.is_array() || j.size() != 3) throw Bad{where + " is not a point [x, y, z]"};
  Vec3 p;
  for (int k = 0; k < 3; ++k) {
    if (!j[k].is_number()) throw Bad{where + " has a coordinate that is not a number (NaN is written as null)"};
    p[k] = j[k].get<double>();
  }
  if (!is_finite(p)) throw Bad{where + " is not finite"};
  return p;
}

uint32_t read_index(const json& j, size_t limit, const std::string& where) {
  if (!j.is_number_unsigned() || j.get<uint64_t>() >= limit) throw Bad{where + " is not an index below " + std::to_string(limit)};
  return static_cast<uint32_t>(j.get<uint64_t>());
}

}  // namespace

Result<Mesh> network_from_json(std::string_view text, const std::string& source) {
  json doc = json::parse(text.begin(), text.end(), nullptr, /*allow_exceptions=*/false);
  if (doc.is_discarded()) return Result<Mesh>::failure(source + ": not valid JSON (truncated or corrupt network file)");
  try {
    if (!doc.is_object() || doc.value("format", std::string()) != "fire-network")
      throw Bad{"not a FIRE curve network (\"format\" must be \"fire-network\")"};
    const json& version = field(doc, "version", "the file");
    if (!version.is_number_integer() || version.get<int64_t>() != 1)
      throw Bad{"unsupported network version " + version.dump() + " (this build reads version 1)"};
    const json& vs = field(doc, "vertices", "the file");
    const json& es = field(doc, "edges", "the file");
    const json& fs = field(doc, "faces", "the file");
    if (!vs.is_array() || !es.is_array() || !fs.is_array()) throw Bad{"vertices, edges and faces must be arrays"};
    Mesh m;
    for (size_t i = 0; i < vs.size(); ++i) {
      std::string where = "vertex " + std::to_string(i);
      const json& split = field(vs[i], "split", where);
      if (!split.is_boolean()) throw Bad{where + ": \"split\" must be true or false"};
      m.add_vertex(read_point(field(vs[i], "p", where), where), split.get<bool>() ? kSplitVertex : 0);
    }
    std::vector<Vec3> line;
    for (size_t i = 0; i < es.size(); ++i) {
      std::string where = "edge " + std::to_string(i);
      const json& ev = field(es[i], "v", where);
      if (!ev.is_array() || ev.size() != 2) throw Bad{where + ": \"v\" must be two vertex indices"};
      const VertexIndex a{read_index(ev[0], vs.size(), where + " vertex")}, b{read_index(ev[1], vs.size(), where + " vertex")};
      if (a == b) throw Bad{where + " joins vertex " + std::to_string(a) + " to itself"};
      const json& pts = field(es[i], "points", where);
      if (!pts.is_array() || pts.size() < 2) throw Bad{where + " needs a polyline of at least 2 points"};
      line.clear();
      for (size_t k = 0; k < pts.size(); ++k) line.push_back(read_point(pts[k], where + " point " + std::to_string(k)));
      if (line.front() != m.vertices.position[a] || line.back() != m.vertices.position[b])
        throw Bad{where + "'s polyline does not start and end at its vertices"};
      const json& sharp = field(es[i], "sharp", where);
      if (!sharp.is_boolean()) throw Bad{where + ": \"sharp\" must be true or false"};
      const EdgeIndex e = m.add_edge(a, b, line);
      if (sharp.get<bool>()) m.set_edge_flag(e, kSharpEdge, true);
      for (const auto& [name, flag] : {std::pair{"bridge", kBridgeEdge}, std::pair{"pending", kPendingEdge}})
        if (const auto on = es[i].find(name); on != es[i].end()) {
          if (!on->is_boolean()) throw Bad{where + ": \"" + name + "\" must be true or false"};
          if (on->get<bool>()) m.set_edge_flag(e, flag, true);
        }
    }
    std::vector<OrientedEdge> loop;
    for (size_t i = 0; i < fs.size(); ++i) {
      std::string where = "face " + std::to_string(i);
      const json& fe = field(fs[i], "edges", where);
      const json& fr = field(fs[i], "reversed", where);
      if (!fe.is_array() || !fr.is_array() || fe.size() != fr.size()) throw Bad{where + ": \"edges\" and \"reversed\" must be arrays of one length"};
      if (fe.size() < 2) throw Bad{where + " has fewer than 2 edges"};
      loop.clear();
      for (size_t k = 0; k < fe.size(); ++k) {
        if (!fr[k].is_boolean()) throw Bad{where + ": \"reversed\" holds a non-boolean"};
        loop.push_back(make_oriented(EdgeIndex{read_index(fe[k], es.size(), where + " edge")}, fr[k].get<bool>()));
      }
      if (m.add_face(loop) == kNone)
        throw Bad{where + " is not a closed loop of edges, repeats an edge, or walks an edge in a direction another face already walks"};
    }
    std::string problem = m.validate();
    if (!problem.empty()) throw Bad{problem};
    return m;
  } catch (const Bad& bad) {
    return Result<Mesh>::failure(source + ": " + bad.why);
  } catch (const json::exception& e) {
    return Result<Mesh>::failure(source + ": malformed network file (" + std::string(e.what()) + ")");
  }
}

std::string network_to_obj(const Mesh& m) {
  std::string out = "# FIRE curve network: one polyline (l) per edge\n";
  std::vector<uint32_t> vertex_index(m.vertex_slots(), 0);
  uint32_t next = 1;
  auto v_line = [&](const Vec3& p) {
    out += "v " + format_double(p.x()) + ' ' + format_double(p.y()) + ' ' + format_double(p.z()) + '\n';
    return next++;
  };
  for (VertexIndex v{0}; v < m.vertex_slots(); ++v)
    if (m.vertex_alive(v)) vertex_index[v] = v_line(m.vertices.position[v]);
  for (EdgeIndex e{0}; e < m.edge_slots(); ++e) {
    if (!m.edge_alive(e)) continue;
    auto line = m.polyline(e);
    std::string l = "l " + std::to_string(vertex_index[m.edges.vertex[e][0]]);
    for (size_t k = 1; k + 1 < line.size(); ++k) l += ' ' + std::to_string(v_line(line[k]));
    l += ' ' + std::to_string(vertex_index[m.edges.vertex[e][1]]) + '\n';
    out += l;
  }
  return out;
}

}  // namespace fire
