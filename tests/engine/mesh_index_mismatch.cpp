// Built only by the mesh_index_mismatch_* tests, once per CASE: an element index of the wrong kind, or a bare
// number, where the Mesh asks for a typed index must not compile (cases 1 and 2); case 0, the same calls with
// the right kinds, compiles.
#include <cstdint>

#include "engine/mesh.hpp"

int main() {
  const fire::Mesh m;
#if CASE == 0
  const fire::FaceIndex f{0};
  const fire::EdgeIndex e{0};
  return m.face_alive(f) && m.edge_alive(e) ? int(m.polyline(e).size()) : 0;
#elif CASE == 1  // an edge where a face is asked for
  const fire::EdgeIndex e{0};
  return m.face_alive(e);
#elif CASE == 2  // a bare number where an edge is asked for
  const uint32_t e = 0;
  return int(m.polyline(e).size());
#endif
}
