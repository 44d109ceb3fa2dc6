#pragma once
// A Catmull-Clark subdivision cage as FIRE builds its surfaces on one (systems/catmull_clark/catmull_clark.hpp's rules):
// what `fire reconstruct --cage` exports for subdivision modellers and what the CAD export converts.
#include <cstdint>
#include <vector>

#include "engine/polygon_mesh.hpp"
#include "engine/surface.hpp"

namespace fire {

struct Cage {
  PolygonMesh mesh;  // faces counter-clockwise seen from outside
  std::vector<uint32_t> sharp_edges;  // vertex pairs of infinitely sharp creases
  // Per vertex, 1 where the border is a corner; the other border vertices are smooth points of their border,
  // which is OpenSubdiv's EdgeOnly boundary with these vertices infinitely sharp. Empty: EdgeAndCorner (a
  // border vertex with a single face is a corner).
  std::vector<uint8_t> border_corners;
  uint32_t levels = 0;  // the surface's level
  SurfaceMesh surface;  // the level's quads at their limit positions, with limit normals
};

}  // namespace fire
