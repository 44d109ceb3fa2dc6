#pragma once
// The pawn and a short sketch that the simulated rig's tests draw, here and in tests/tools/simulation/.
#include <catch2/catch.hpp>
#include <string>

#include "engine/polygon_mesh.hpp"
#include "platform/obj.hpp"
#include "platform/simulated_rig/simulated_rig.hpp"

namespace fire::simulation::test {

inline const PolygonMesh& pawn() {
  static const PolygonMesh mesh = [] {
    Result<PolygonMesh> m = read_obj(std::string(FIRE_DATA_DIR) + "/meshes/pawn.obj");
    REQUIRE(m.ok());
    return *m;
  }();
  return mesh;
}

inline SketchOptions short_sketch() {
  SketchOptions s;
  s.strokes = 3;
  s.hold_s = 0.6;
  return s;
}

}  // namespace fire::simulation::test
