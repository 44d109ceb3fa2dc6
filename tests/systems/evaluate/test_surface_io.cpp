// Surface export: every format re-read through our readers (glTF through its structural check), atomic
// writes, and clear refusals of bad surfaces, bad paths and corrupt files.
#include <catch2/catch.hpp>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <unistd.h>

#include "platform/files.hpp"
#include "platform/obj.hpp"
#include "platform/surface_io.hpp"

using namespace fire;
using Catch::Matchers::Contains;
namespace fs = std::filesystem;

namespace {

// A folder of its own per test, removed afterwards.
struct TempDir {
  fs::path path;
  TempDir() {
    static int counter = 0;
    path = fs::temp_directory_path() / ("fire_export_eval_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~TempDir() { fs::remove_all(path); }
  std::string file(const std::string& name) const { return (path / name).string(); }
  std::vector<std::string> entries() const {
    std::vector<std::string> out;
    for (const auto& e : fs::directory_iterator(path)) out.push_back(e.path().filename().string());
    std::sort(out.begin(), out.end());
    return out;
  }
};

// A small open surface with a pentagon, quads and a triangle, coordinates that are not exact in float,
// and one normal left zero (the writer must fill it in).
SurfaceMesh house() {
  SurfaceMesh s;
  s.positions = {{0, 0, 0},     {1.1, 0, 0},     {1.1, 1, 0.1},  {0.55, 1.6, 0.2}, {0, 1, 0.1},
                 {0, 0, -1.3},  {1.1, 0, -1.3},  {0.3, -0.7, -0.65}};
  auto face = [&](std::initializer_list<uint32_t> vs) {
    s.face_vertices.insert(s.face_vertices.end(), vs);
    s.face_offsets.push_back(static_cast<uint32_t>(s.face_vertices.size()));
  };
  face({0, 1, 2, 3, 4});  // pentagon
  face({1, 0, 5, 6});     // quad hanging down
  face({0, 7, 5});        // triangle
  s.normals.resize(s.positions.size());
  for (size_t v = 0; v < s.positions.size(); ++v) s.normals[v] = Vec3(0.1 * v, 1, 0.5).normalized();
  s.normals[3] = Vec3::Zero();
  return s;
}

std::string read_bytes(const std::string& path) {
  auto r = read_text_file(path);
  REQUIRE(r.ok());
  return *r;
}

// The value a float file stores. The volatile is needed: g++ 12.2 at -O2/-O3 (SLP vectorizer) drops a
// double -> float -> double round trip done on two or more coordinates at once.
Vec3 as_float(const Vec3& p) {
  Vec3 out;
  for (int k = 0; k < 3; ++k) {
    volatile float rounded = static_cast<float>(p[k]);
    out[k] = rounded;
  }
  return out;
}

// The fan triangles writers produce, as vertex indices.
std::vector<uint32_t> fan(const SurfaceMesh& s) {
  std::vector<uint32_t> out;
  for (size_t f = 0; f < s.face_count(); ++f)
    for (uint32_t c = s.face_offsets[f] + 1; c + 1 < s.face_offsets[f + 1]; ++c)
      out.insert(out.end(), {s.face_vertices[s.face_offsets[f]], s.face_vertices[c], s.face_vertices[c + 1]});
  return out;
}

uint32_t u32_at(const std::string& bytes, size_t at) {
  uint32_t v;
  std::memcpy(&v, bytes.data() + at, 4);
  return v;
}

// Splits a .glb into its JSON and BIN payloads, and builds one back (with correct lengths) from them.
std::pair<nlohmann::json, std::string> split_glb(const std::string& glb) {
  const uint32_t json_length = u32_at(glb, 12);
  return {nlohmann::json::parse(glb.substr(20, json_length)), glb.substr(20 + json_length + 8)};
}
std::string make_glb(const nlohmann::json& doc, const std::string& bin) {
  std::string text = doc.dump();
  text.resize((text.size() + 3) / 4 * 4, ' ');
  auto u32 = [](uint32_t v) { return std::string(reinterpret_cast<const char*>(&v), 4); };
  const uint32_t total = static_cast<uint32_t>(12 + 8 + text.size() + 8 + bin.size());
  return u32(0x46546C67) + u32(2) + u32(total) + u32(static_cast<uint32_t>(text.size())) + u32(0x4E4F534A) + text +
         u32(static_cast<uint32_t>(bin.size())) + u32(0x004E4942) + bin;
}

}  // namespace

TEST_CASE("OBJ export keeps polygons, exact positions and unit normals", "[export]") {
  TempDir dir;
  const SurfaceMesh s = house();
  REQUIRE(write_surface(s, dir.file("house.obj"), LengthUnit::Metre).ok());
  CHECK(dir.entries() == std::vector<std::string>{"house.obj"});  // no temporary file left behind
  auto back = read_surface(dir.file("house.obj"));
  REQUIRE(back.ok());
  CHECK(back->positions == s.positions);  // shortest round-trip text: bit for bit
  CHECK(back->face_offsets == s.face_offsets);
  CHECK(back->face_vertices == s.face_vertices);
  REQUIRE(back->normals.size() == s.positions.size());
  for (size_t v = 0; v < s.positions.size(); ++v) {
    CHECK(back->normals[v].norm() == Approx(1).epsilon(1e-15));
    if (v != 3) CHECK((back->normals[v] - s.normals[v]).norm() < 1e-15);
  }
  // Vertex 3 lies only on the pentagon, so its filled-in normal is the pentagon's.
  const Vec3 pentagon = (s.positions[1] - s.positions[0]).cross(s.positions[2] - s.positions[0]).normalized();
  CHECK(back->normals[3].dot(pentagon) > 0.99);
  const std::string text = read_bytes(dir.file("house.obj"));
  CHECK_THAT(text, Contains("\nf 1//1 2//2 3//3 4//4 5//5\n"));
}

TEST_CASE("binary PLY round-trips at float precision with polygons kept", "[export]") {
  TempDir dir;
  const SurfaceMesh s = house();
  REQUIRE(write_surface(s, dir.file("house.ply"), LengthUnit::Metre).ok());
  const std::string bytes = read_bytes(dir.file("house.ply"));
  CHECK(bytes.starts_with("ply\nformat binary_little_endian 1.0\n"));
  const size_t header = bytes.find("end_header\n") + 11;
  // 8 vertices of 6 floats, then per face a uchar count and int indices.
  CHECK(bytes.size() == header + 8 * 24 + 3 + 4 * (5 + 4 + 3));
  auto back = read_surface(dir.file("house.ply"));
  REQUIRE(back.ok());
  REQUIRE(back->positions.size() == s.positions.size());
  for (size_t v = 0; v < s.positions.size(); ++v) CHECK(back->positions[v] == as_float(s.positions[v]));
  CHECK(back->face_offsets == s.face_offsets);
  CHECK(back->face_vertices == s.face_vertices);
  for (size_t v = 0; v < s.positions.size(); ++v) {
    CHECK(back->normals[v].norm() == Approx(1).epsilon(1e-6));
    if (v != 3) CHECK((back->normals[v] - s.normals[v]).norm() < 1e-7);
  }
}

TEST_CASE("binary STL holds the fan triangles with facet normals", "[export]") {
  TempDir dir;
  const SurfaceMesh s = house();
  REQUIRE(write_surface(s, dir.file("house.STL"), LengthUnit::Metre).ok());  // extensions are case-insensitive
  const std::string bytes = read_bytes(dir.file("house.STL"));
  CHECK(bytes.substr(0, 5) != "solid");  // would read as ASCII STL
  const std::vector<uint32_t> tris = fan(s);
  REQUIRE(tris.size() == 3 * 6);  // 3 + 2 + 1 triangles from the faces of 5, 4 and 3 vertices
  CHECK(bytes.size() == 84 + 50 * 6);
  auto back = read_surface(dir.file("house.STL"));
  REQUIRE(back.ok());
  REQUIRE(back->face_count() == 6);
  for (size_t t = 0; t < 6; ++t) {
    REQUIRE(back->face_size(t) == 3);
    for (int k = 0; k < 3; ++k)
      CHECK(back->positions[back->face_vertices[3 * t + k]] == as_float(s.positions[tris[3 * t + k]]));
    const Vec3& a = s.positions[tris[3 * t]];
    const Vec3 facet = (s.positions[tris[3 * t + 1]] - a).cross(s.positions[tris[3 * t + 2]] - a).normalized();
    CHECK((back->normals[3 * t] - facet).norm() < 1e-6);
  }
}

TEST_CASE("ASCII STL reads as the binary one does, and a binary header that starts with solid stays binary", "[export]") {
  const std::string ascii =
      "solid two\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n   vertex 1 0 0\n   vertex 0 1 0\n  endloop\n endfacet\n"
      " facet normal 0 0 -1\n  outer loop\n   vertex 0 0 0\n   vertex 0 1 0\n   vertex 1 0 0.5e-1\n  endloop\n endfacet\n"
      "endsolid two\n";
  auto r = decode_surface(ascii, SurfaceFormat::Stl, "two.stl");
  INFO((r.ok() ? "" : r.error()));
  REQUIRE(r.ok());
  REQUIRE(r->face_count() == 2);
  CHECK(r->positions.size() == 6);
  CHECK(r->positions[5] == Vec3(1, 0, double(0.05f)));  // kept as the float STL holds
  CHECK(r->normals[3] == Vec3(0, 0, -1));
  // A binary file whose 80-byte header happens to begin with "solid": its size matches the binary layout.
  TempDir dir;
  REQUIRE(write_surface(house(), dir.file("a.stl")).ok());
  std::string binary = read_bytes(dir.file("a.stl"));
  binary.replace(0, 5, "solid");
  auto b = decode_surface(binary, SurfaceFormat::Stl, "b.stl");
  REQUIRE(b.ok());
  CHECK(b->face_count() == 6);
  auto refuse = [](const std::string& text, const char* part) {
    auto bad = decode_surface(text, SurfaceFormat::Stl, "bad.stl");
    REQUIRE_FALSE(bad.ok());
    CHECK_THAT(bad.error(), Contains(part));
  };
  refuse("solid\nendsolid\n", "bad.stl:2: ASCII STL: no triangles");
  refuse(ascii.substr(0, ascii.size() - 13), "ends before 'endsolid'");
  refuse(std::string(ascii).replace(ascii.find("1 0 0\n"), 5, "1 nan"), "bad.stl:5: ASCII STL: expected 'vertex' and three numbers a float holds");
  refuse(std::string(ascii).replace(ascii.find("1 0 0\n"), 5, "1e39 0"), "bad.stl:5: ASCII STL: expected 'vertex' and three numbers a float holds");
  refuse(std::string(ascii).replace(ascii.find("endloop"), 7, "vertex 1 1 1\n  endloop"), "only triangles are STL facets");
}

TEST_CASE("glTF binary passes the structural check and reads back", "[export][gltf]") {
  TempDir dir;
  const SurfaceMesh s = house();
  REQUIRE(write_surface(s, dir.file("house.glb")).ok());
  const std::string bytes = read_bytes(dir.file("house.glb"));
  auto summary = check_glb(bytes, "house.glb");
  REQUIRE(summary.ok());
  CHECK(summary->total_length == bytes.size());
  CHECK(summary->json_length % 4 == 0);
  CHECK(summary->bin_length == 8 * 12 * 2 + 6 * 3 * 4);  // positions, normals, uint32 indices
  CHECK(summary->vertex_count == 8);
  CHECK(summary->index_count == 18);
  // Stored +Y up, as glTF has it: FIRE's z is glTF's y, FIRE's y is glTF's -z.
  CHECK(summary->position_min.x() == 0);
  CHECK(summary->position_max.x() == Approx(1.1).epsilon(1e-7));
  CHECK(summary->position_min.y() == Approx(-1.3).epsilon(1e-7));
  CHECK(summary->position_max.y() == Approx(0.2).epsilon(1e-7));
  CHECK(summary->position_min.z() == Approx(-1.6).epsilon(1e-7));
  CHECK(summary->position_max.z() == Approx(0.7).epsilon(1e-7));

  auto [doc, bin] = split_glb(bytes);
  CHECK(doc["asset"]["version"] == "2.0");
  CHECK(doc["buffers"][0]["byteLength"] == bin.size());
  CHECK(doc["accessors"][2]["componentType"] == 5125);  // UNSIGNED_INT indices
  CHECK(doc["accessors"][0]["min"].size() == 3);

  auto back = read_surface(dir.file("house.glb"));
  REQUIRE(back.ok());
  CHECK(back->face_vertices == fan(s));
  for (size_t v = 0; v < s.positions.size(); ++v) {
    CHECK(back->positions[v] == as_float(s.positions[v]));
    CHECK(back->normals[v].norm() == Approx(1).epsilon(1e-6));
  }
}

TEST_CASE("corrupt glTF binaries fail the structural check, naming the check", "[export][gltf][reject]") {
  TempDir dir;
  REQUIRE(write_surface(house(), dir.file("house.glb")).ok());
  const std::string good = read_bytes(dir.file("house.glb"));
  auto refuse = [](const std::string& bytes, const char* part) {
    auto r = check_glb(bytes, "bad.glb");
    REQUIRE_FALSE(r.ok());
    CHECK_THAT(r.error(), Contains("bad.glb"));
    CHECK_THAT(r.error(), Contains(part));
  };
  refuse(good.substr(0, 8), "too short");
  std::string magic = good;
  magic[0] = 'x';
  refuse(magic, "magic");
  std::string version = good;
  version[4] = 1;
  refuse(version, "version 1");
  refuse(good + "pad!", "differs from the file size");
  refuse(good.substr(0, good.size() - 4), "differs from the file size");
  std::string chunk_type = good;
  chunk_type[16] = 'X';
  refuse(chunk_type, "not the JSON chunk");

  auto [doc, bin] = split_glb(good);
  REQUIRE(check_glb(make_glb(doc, bin), "bad.glb").ok());  // the rebuild itself is faithful
  refuse(make_glb(doc, bin.substr(0, bin.size() - 4)), "does not match the BIN chunk");
  auto too_many = doc;
  too_many["accessors"][0]["count"] = 9;
  refuse(make_glb(too_many, bin), "POSITION accessor needs");
  auto view_past = doc;
  view_past["bufferViews"][2]["byteLength"] = 100;  // from byte 192, past the 264-byte buffer
  refuse(make_glb(view_past, bin), "bufferView 2");
  auto no_min = doc;
  no_min["accessors"][0].erase("min");
  refuse(make_glb(no_min, bin), "min/max");
  auto wrong_max = doc;
  wrong_max["accessors"][0]["max"][1] = 7.0;
  refuse(make_glb(wrong_max, bin), "min/max do not match");
  auto old_asset = doc;
  old_asset["asset"]["version"] = "1.0";
  refuse(make_glb(old_asset, bin), "asset.version");
  auto no_indices = doc;
  no_indices["meshes"][0]["primitives"][0].erase("indices");
  refuse(make_glb(no_indices, bin), "malformed glTF JSON");
  std::string bad_index = bin;
  const uint32_t big = 99;
  std::memcpy(bad_index.data() + bin.size() - 4, &big, 4);
  refuse(make_glb(doc, bad_index), "not below the vertex count");
  std::string not_json = make_glb(doc, bin);
  not_json[20] = '[';
  refuse(not_json, "not a JSON object");
}

TEST_CASE("corrupt PLY and STL files are refused with the file and the problem", "[export][reject]") {
  TempDir dir;
  REQUIRE(write_surface(house(), dir.file("a.ply")).ok());
  REQUIRE(write_surface(house(), dir.file("a.stl")).ok());
  const std::string ply = read_bytes(dir.file("a.ply")), stl = read_bytes(dir.file("a.stl"));
  auto refuse = [](const std::string& bytes, SurfaceFormat format, const char* part) {
    auto r = decode_surface(bytes, format, "bad.file");
    REQUIRE_FALSE(r.ok());
    CHECK_THAT(r.error(), Contains("bad.file"));
    CHECK_THAT(r.error(), Contains(part));
  };
  refuse(ply.substr(0, ply.size() - 1), SurfaceFormat::Ply, "truncated in face 2");
  refuse(ply.substr(0, ply.find("end_header") + 20), SurfaceFormat::Ply, "truncated: 8 vertices");
  refuse(ply + "x", SurfaceFormat::Ply, "1 bytes after the last face");
  refuse(std::string(ply).replace(ply.find("float nz"), 8, "double n"), SurfaceFormat::Ply, "unsupported PLY layout");
  refuse(std::string(ply).replace(ply.find("binary_little"), 13, "binary_bigxxx"), SurfaceFormat::Ply,
         "unsupported PLY layout");
  refuse("solid x\nendsolid\n", SurfaceFormat::Ply, "not a PLY file");
  std::string nan_ply = ply;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::memcpy(nan_ply.data() + ply.find("end_header") + 11 + 24 * 2 + 4, &nan, 4);
  refuse(nan_ply, SurfaceFormat::Ply, "vertex 2 has a non-finite value");
  refuse(stl.substr(0, stl.size() - 1), SurfaceFormat::Stl, "must have 384 bytes, found 383");
  refuse(stl.substr(0, 50), SurfaceFormat::Stl, "too short");
  std::string nan_stl = stl;
  std::memcpy(nan_stl.data() + 84 + 50 * 4 + 12, &nan, 4);
  refuse(nan_stl, SurfaceFormat::Stl, "triangle 4 has a non-finite value");
  refuse("v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 nan\nf 1 2 3\n", SurfaceFormat::Obj, "bad.file:4: normal coordinate");
}

TEST_CASE("bad surfaces and paths are refused and leave no file", "[export][reject]") {
  TempDir dir;
  auto refuse = [&](const SurfaceMesh& s, const std::string& name, const char* part) {
    const Status st = write_surface(s, dir.file(name));
    REQUIRE_FALSE(st.ok());
    CHECK_THAT(st.error, Contains(name));
    CHECK_THAT(st.error, Contains(part));
    CHECK(dir.entries().empty());  // neither the file nor a temporary one
  };
  refuse(house(), "house.xyz", "unknown surface format 'xyz'");
  refuse(house(), "house", "unknown surface format ''");
  refuse(SurfaceMesh{}, "empty.obj", "no vertices");
  SurfaceMesh no_faces = house();
  no_faces.face_offsets = {0};
  no_faces.face_vertices.clear();
  refuse(no_faces, "no_faces.ply", "no faces");
  for (const char* ext : {"obj", "ply", "stl", "glb"}) {
    SurfaceMesh nan = house();
    nan.positions[4].y() = std::numeric_limits<double>::quiet_NaN();
    refuse(nan, std::string("nan.") + ext, "vertex 4 has a non-finite coordinate");
  }
  SurfaceMesh nan_normal = house();
  nan_normal.normals[2].x() = std::numeric_limits<double>::infinity();
  refuse(nan_normal, "n.glb", "normal 2 is not finite");
  SurfaceMesh few_normals = house();
  few_normals.normals.pop_back();
  refuse(few_normals, "n.obj", "7 normals for 8 vertices");
  SurfaceMesh bad_index = house();
  bad_index.face_vertices[6] = 8;
  refuse(bad_index, "i.stl", "face 1 refers to vertex 8 of 8");
  SurfaceMesh two_sided = house();
  two_sided.face_offsets[1] = 2;
  refuse(two_sided, "t.obj", "face 0 has fewer than 3 vertices");
  SurfaceMesh huge = house();
  huge.positions[0].x() = 1e39;
  refuse(huge, "huge.glb", "beyond the 32-bit float range");
  SurfaceMesh many;  // one 300-gon: fine in OBJ, too big for a PLY uchar list
  for (uint32_t k = 0; k < 300; ++k) {
    many.positions.push_back({std::cos(k * 0.0209), std::sin(k * 0.0209), 0});
    many.face_vertices.push_back(k);
  }
  many.face_offsets.push_back(300);
  refuse(many, "many.ply", "face 0 has 300 vertices");
  REQUIRE(write_surface(many, dir.file("many.obj")).ok());
  fs::remove(dir.file("many.obj"));

  const Status missing_dir = write_surface(house(), dir.file("no/such/dir/out.obj"));
  REQUIRE_FALSE(missing_dir.ok());
  CHECK_THAT(missing_dir.error, Contains("no/such/dir/out.obj"));
  CHECK_THAT(missing_dir.error, Contains("cannot write"));
  CHECK(dir.entries().empty());
}

TEST_CASE("a failed export leaves an existing file untouched", "[export][reject]") {
  TempDir dir;
  REQUIRE(write_surface(house(), dir.file("keep.ply")).ok());
  const std::string before = read_bytes(dir.file("keep.ply"));
  SurfaceMesh nan = house();
  nan.positions[0].z() = std::numeric_limits<double>::quiet_NaN();
  REQUIRE_FALSE(write_surface(nan, dir.file("keep.ply")).ok());
  CHECK(read_bytes(dir.file("keep.ply")) == before);
  CHECK(dir.entries() == std::vector<std::string>{"keep.ply"});
}

TEST_CASE("a surface without normals gets area-weighted ones", "[export]") {
  TempDir dir;
  SurfaceMesh s = house();
  s.normals.clear();
  REQUIRE(write_surface(s, dir.file("plain.obj")).ok());
  auto back = read_surface(dir.file("plain.obj"));
  REQUIRE(back.ok());
  REQUIRE(back->normals.size() == s.positions.size());
  // Vertex 7 lies only on the triangle (0, 7, 5): its normal is that triangle's.
  const Vec3 triangle = (s.positions[7] - s.positions[0]).cross(s.positions[5] - s.positions[0]).normalized();
  CHECK((back->normals[7] - triangle).norm() < 1e-12);
}

TEST_CASE("mesh exports are in millimetres by default, say so, and read back in metres", "[export][units]") {
  TempDir dir;
  const SurfaceMesh s = house();
  double height = 0;
  for (const Vec3& p : s.positions) height = std::max(height, p.z());
  for (const char* name : {"house.obj", "house.ply", "house.stl"}) {
    INFO(name);
    REQUIRE(write_surface(s, dir.file(name)).ok());
    const std::string bytes = read_bytes(dir.file(name));
    CHECK((bytes.find("units: mm") != std::string::npos || bytes.find("comment units mm\n") != std::string::npos));
    CHECK((bytes.find("up: +Z") != std::string::npos || bytes.find("comment up +Z\n") != std::string::npos));
    auto back = read_surface(dir.file(name));
    REQUIRE(back.ok());
    double back_height = 0;
    for (const Vec3& p : back->positions) back_height = std::max(back_height, p.z());
    CHECK(back_height == Approx(height).epsilon(1e-7));  // metres again, at float precision for PLY and STL
  }
  // The numbers in the file are millimetres.
  const std::string obj = read_bytes(dir.file("house.obj"));
  auto raw = parse_obj(obj.substr(obj.find("\nv ")), "body");  // without the units line: the numbers as written
  REQUIRE(raw.ok());
  for (size_t v = 0; v < s.positions.size(); ++v) CHECK((raw->positions[v] - 1000 * s.positions[v]).norm() <= 1e-12 * 1000);
  REQUIRE(write_surface(s, dir.file("cm.obj"), LengthUnit::Centimetre).ok());
  CHECK(read_bytes(dir.file("cm.obj")).find("# units: cm, up: +Z\n") != std::string::npos);
  // glTF is metres whatever is asked.
  REQUIRE(write_surface(s, dir.file("a.glb"), LengthUnit::Millimetre).ok());
  auto glb = read_surface(dir.file("a.glb"));
  REQUIRE(glb.ok());
  for (size_t v = 0; v < s.positions.size(); ++v) CHECK((glb->positions[v] - s.positions[v]).norm() < 1e-6);
}

TEST_CASE("a unit a file names that is not one of ours is refused, naming it", "[export][units]") {
  auto obj = parse_obj("# units: furlong, up: +Z\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "odd.obj");
  REQUIRE(!obj.ok());
  CHECK_THAT(obj.error(), Contains("odd.obj:1") && Contains("furlong"));
  CHECK(length_unit_of("cm").ok());
  CHECK(!length_unit_of("inch").ok());
}
