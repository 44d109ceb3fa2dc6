// The exported cage (platform/cage_io.hpp) against OpenSubdiv: read back from USDA and from OBJ's tags, refined
// and pushed to the limit by OpenSubdiv under the rules the file states, it gives FIRE's surface.
#include <catch2/catch.hpp>

#include <charconv>
#include <string>

#include "osd_reference.hpp"
#include "platform/cage_io.hpp"
#include "platform/obj.hpp"
#include "systems/reconstruct/reconstruct.hpp"
#include "systems/synth/network_from_mesh.hpp"

namespace {

namespace osd = fire::osd_reference;
using fire::Cage;
using fire::Vec3;

Cage pawn_cage(bool with_crease) {
  auto mesh = fire::read_obj(std::string(FIRE_DATA_DIR) + "/meshes/pawn.obj");
  REQUIRE(mesh.ok());
  auto net = fire::network_from_mesh(mesh->view(), fire::UnrefineOptions{.unrefine = 2, .limit = true});
  REQUIRE(net.ok());
  if (with_crease) {
    // Every curve of one face of the network, sharp: the cage gets creases and the surface a ridge.
    fire::FaceIndex face{0};
    while (!net->face_alive(face)) ++face;
    for (fire::EdgeIndex e{0}; e < net->edge_slots(); ++e)
      if (net->edge_alive(e) && (net->edges.face[e][0] == face || net->edges.face[e][1] == face))
        net->set_edge_flag(e, fire::kSharpEdge, true);
  }
  fire::reconstruct::Options options;
  options.levels = 2;
  auto cage = fire::reconstruct::reconstruct_cage(*net, options);
  INFO(cage.error());
  REQUIRE(cage.ok());
  return *cage;
}

// OpenSubdiv's limit of `cage` under the rules it states (EdgeOnly with corners, or EdgeAndCorner), at FIRE's
// level, compared corner by corner with FIRE's surface (the last level's faces keep OpenSubdiv's numbering).
double largest_difference(const Cage& cage, const fire::SurfaceMesh& surface) {
  namespace Far = OpenSubdiv::Far;
  namespace Sdc = OpenSubdiv::Sdc;
  const fire::PolygonMesh& m = cage.mesh;
  std::vector<int> sizes(m.face_count());
  for (size_t f = 0; f < sizes.size(); ++f) sizes[f] = int(m.face_size(f));
  std::vector<Far::Index> indices(m.face_vertices.begin(), m.face_vertices.end());
  std::vector<Far::Index> crease_pairs(cage.sharp_edges.begin(), cage.sharp_edges.end());
  std::vector<float> crease_weights(cage.sharp_edges.size() / 2, Sdc::Crease::SHARPNESS_INFINITE);
  std::vector<Far::Index> corners;
  for (uint32_t v = 0; v < cage.border_corners.size(); ++v)
    if (cage.border_corners[v]) corners.push_back(Far::Index(v));
  std::vector<float> corner_weights(corners.size(), Sdc::Crease::SHARPNESS_INFINITE);
  Far::TopologyDescriptor d;
  d.numVertices = int(m.positions.size());
  d.numFaces = int(sizes.size());
  d.numVertsPerFace = sizes.data();
  d.vertIndicesPerFace = indices.data();
  d.numCreases = int(crease_weights.size());
  d.creaseVertexIndexPairs = crease_pairs.data();
  d.creaseWeights = crease_weights.data();
  d.numCorners = int(corners.size());
  d.cornerVertexIndices = corners.data();
  d.cornerWeights = corner_weights.data();
  Sdc::Options options;
  options.SetVtxBoundaryInterpolation(cage.border_corners.empty() ? Sdc::Options::VTX_BOUNDARY_EDGE_AND_CORNER
                                                                  : Sdc::Options::VTX_BOUNDARY_EDGE_ONLY);
  using Factory = Far::TopologyRefinerFactory<Far::TopologyDescriptor>;
  std::unique_ptr<Far::TopologyRefiner> refiner(Factory::Create(d, Factory::Options(Sdc::SCHEME_CATMARK, options)));
  Far::TopologyRefiner::UniformOptions uniform(int(cage.levels));
  uniform.fullTopologyInLastLevel = true;
  refiner->RefineUniform(uniform);
  const auto levels = osd::interpolate(*refiner, m.positions);
  const osd::Limit limit = osd::limit(*refiner, levels.back());
  const Far::TopologyLevel& last = refiner->GetLevel(int(cage.levels));
  REQUIRE(size_t(last.GetNumFaces()) == surface.face_count());
  double worst = 0;
  for (int f = 0; f < last.GetNumFaces(); ++f) {
    const auto verts = last.GetFaceVertices(f);
    REQUIRE(verts.size() == int(surface.face_size(size_t(f))));
    for (int k = 0; k < verts.size(); ++k) {
      const Vec3 theirs = limit.positions[size_t(verts[k])].vec();
      const Vec3 ours = surface.positions[surface.face_vertices[surface.face_offsets[size_t(f)] + uint32_t(k)]];
      worst = std::max(worst, (theirs - ours).norm());
    }
  }
  return worst;
}

double diagonal(const std::vector<Vec3>& points) {
  Vec3 lo = points[0], hi = points[0];
  for (const Vec3& p : points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  return (hi - lo).norm();
}

}  // namespace

TEST_CASE("the exported USDA cage's OpenSubdiv limit is FIRE's surface", "[cage][opensubdiv]") {
  for (const bool crease : {false, true}) {
    INFO((crease ? "with a sharp face outline" : "no sharp curves"));
    const Cage cage = pawn_cage(crease);
    CHECK(!cage.border_corners.empty());
    CHECK((cage.sharp_edges.size() > 0) == crease);
    auto text = fire::encode_cage_usda(cage, fire::LengthUnit::Millimetre);
    REQUIRE(text.ok());
    CHECK(text->find("metersPerUnit = 0.001") != std::string::npos);
    CHECK(text->find("interpolateBoundary = \"edgeOnly\"") != std::string::npos);
    CHECK((text->find("creaseSharpnesses") != std::string::npos) == crease);
    auto back = fire::decode_cage_usda(*text, "cage.usda");
    INFO(back.error());
    REQUIRE(back.ok());
    back->levels = cage.levels;
    CHECK(back->mesh.face_offsets == cage.mesh.face_offsets);
    CHECK(back->mesh.face_vertices == cage.mesh.face_vertices);
    CHECK(back->sharp_edges == cage.sharp_edges);
    const double diag = diagonal(cage.surface.positions);
    // USD's points are floats, here in millimetres.
    CHECK(largest_difference(*back, cage.surface) <= 1e-6 * diag);
  }
}

TEST_CASE("the exported OBJ cage carries OpenSubdiv's tags for its border, creases and corners", "[cage]") {
  const Cage cage = pawn_cage(true);
  auto text = fire::encode_cage_obj(cage, fire::LengthUnit::Metre);
  REQUIRE(text.ok());
  auto polygons = fire::parse_obj(*text, "cage.obj");
  REQUIRE(polygons.ok());
  CHECK(polygons->face_vertices == cage.mesh.face_vertices);
  Cage read;
  read.mesh = *polygons;
  read.levels = cage.levels;
  read.border_corners.assign(read.mesh.positions.size(), 0);
  size_t boundary_tags = 0;
  for (size_t at = text->find("\nt "); at != std::string::npos; at = text->find("\nt ", at + 1)) {
    const std::string line = text->substr(at + 1, text->find('\n', at + 1) - at - 1);
    uint32_t a = 0, b = 0;
    if (line.starts_with("t interpolateboundary 1/0/0 ")) {
      ++boundary_tags;
      CHECK(line.back() == '2');  // EdgeOnly
    } else if (std::sscanf(line.c_str(), "t crease 2/1/0 %u %u 10", &a, &b) == 2) {
      read.sharp_edges.insert(read.sharp_edges.end(), {a, b});
    } else if (std::sscanf(line.c_str(), "t corner 1/1/0 %u 10", &a) == 1) {
      read.border_corners.at(a) = 1;
    } else FAIL("unexpected tag: " << line);
  }
  CHECK(boundary_tags == 1);
  CHECK(read.sharp_edges == cage.sharp_edges);
  CHECK(largest_difference(read, cage.surface) <= 1e-9 * diagonal(cage.surface.positions));
}

TEST_CASE("a cage path of another format is refused, naming it", "[cage]") {
  const fire::Status s = fire::check_cage_path("out/cage.fbx");
  REQUIRE(!s);
  CHECK(s.error.find("cage.fbx") != std::string::npos);
  CHECK(s.error.find(".usda") != std::string::npos);
  CHECK(!fire::decode_cage_usda("#usda 1.0\ndef Mesh \"m\" {}\n", "bad.usda"));
}
