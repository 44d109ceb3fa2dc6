#pragma once
// CAD export through OpenCASCADE: bicubic B-spline patches (engine/bspline.hpp) as STEP (AP214) or IGES
// (5.3, BRep mode: faces in shells), each patch one face, sewn into one shell whose free edges are the
// object's borders; a closed shell becomes a solid. Written in millimetres unless asked otherwise, with the
// unit in the file. A build without OpenCASCADE (FIRE_HAVE_OCCT undefined) compiles this too, and every
// call then fails with a message that says so.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "engine/bspline.hpp"
#include "engine/common.hpp"
#include "platform/surface_io.hpp"

namespace fire::cad {

enum class CadFormat : uint8_t { Step, Iges };
// By the path's extension, .step / .stp or .igs / .iges in any case; anything else is an error naming the path.
Result<CadFormat> cad_format_of(const std::string& path);

// Whether this build has OpenCASCADE, so that write_cad and read_cad can work.
bool cad_available();

// What write_cad made.
struct CadWritten {
  size_t faces = 0;                // one per patch
  size_t shells = 0, solids = 0;   // closed shells are solids, and counted only there
  size_t free_edges = 0;           // edges of one face: the object's borders
  double sewing_tolerance = 0;     // in the file's unit
};

// Writes `patches` (positions in metres) to `path` as STEP or IGES by its extension, in `unit` (the mesh
// exports' unit, platform/surface_io.hpp), which the file states; atomic: a failed write leaves nothing at
// `path`. Errors name the path and the problem (the extension, no patches, a patch OpenCASCADE cannot make a
// face of, a folder that cannot be written, no OpenCASCADE in this build).
Result<CadWritten> write_cad(const BsplinePatches& patches, const std::string& path,
                             LengthUnit unit = kDefaultExportUnit);

// A STEP or IGES file read back with OpenCASCADE, for tests and measurements.
struct CadShapeInfo {
  bool valid = false;              // BRepCheck_Analyzer finds the shape valid
  size_t faces = 0, shells = 0, solids = 0;
  size_t free_edges = 0;           // edges of one face only (degenerate edges left out)
  std::vector<Vec3> free_edge_middles;  // the point halfway along each of them, in the file's unit
  std::string unit;                // the file's length unit: "mm", "cm", "m" or "in" (others are refused)
  // The box around the surfaces' control points, which the surfaces lie in, in the file's unit.
  Vec3 box_min = Vec3::Zero(), box_max = Vec3::Zero();
  // With samples_per_side n > 1: each face's surface at n x n points of its parameter range, row by row, face
  // after face, in the file's unit.
  std::vector<Vec3> samples;
};
Result<CadShapeInfo> read_cad(const std::string& path, uint32_t samples_per_side = 0);

}  // namespace fire::cad
