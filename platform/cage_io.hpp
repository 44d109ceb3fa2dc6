#pragma once
// The subdivision cage out (`fire reconstruct --cage`), for subdivision modellers: OBJ with OpenSubdiv's tags
// (`t interpolateboundary`, `t crease`, `t corner`; vertex indices from 0 as OpenSubdiv's shapes have them)
// and USD's text form (a Mesh prim: subdivisionScheme catmullClark, interpolateBoundary, creaseIndices,
// creaseLengths, creaseSharpnesses, cornerIndices, cornerSharpnesses; metersPerUnit and upAxis Z on the stage).
// Infinitely sharp is sharpness 10, OpenSubdiv's Sdc::Crease::SHARPNESS_INFINITE. Both in the LengthUnit asked,
// saying which; both written atomically. The USDA reader takes back what the writer produces, for tests.
#include <string>
#include <string_view>

#include "engine/cage.hpp"
#include "engine/common.hpp"
#include "platform/surface_io.hpp"

namespace fire {

inline constexpr double kInfiniteSharpness = 10.0;

// From the extension: .obj or .usda; an error names the path and the two known.
Status check_cage_path(const std::string& path);
// `title`, when given, is the file's first line (a comment saying what the cage is).
Result<std::string> encode_cage_obj(const Cage& cage, LengthUnit unit, std::string_view title = {});
Result<std::string> encode_cage_usda(const Cage& cage, LengthUnit unit);
Status write_cage(const Cage& cage, const std::string& path, LengthUnit unit = kDefaultExportUnit);

// The cage of a USDA file as encode_cage_usda writes it, positions in metres; `levels` and `surface` stay empty.
Result<Cage> decode_cage_usda(std::string_view text, const std::string& source);

}  // namespace fire
