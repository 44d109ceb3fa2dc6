#pragma once
// Hand-made curve networks for the reconstruction tests.
#include <cmath>
#include <cstring>
#include <functional>
#include <optional>
#include <random>
#include <vector>

#include "engine/edit_command.hpp"
#include "engine/mesh.hpp"
#include "systems/split/edit.hpp"

namespace fire::test {

using Height = std::function<double(double, double)>;

// The bumpy field the random-edit tests lay their grids over.
inline double random_edit_height(double x, double y) { return 0.4 * std::sin(0.7 * x) * std::cos(0.6 * y); }

// Equal bit for bit: what an incremental surface must be to a reconstruction from scratch.
template <class T>
bool same_bytes(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

// One face with n sides (n >= 2): corners on the unit circle at angles 2 pi k / n, each side the arc
// of the circle between its corners lifted to z = 0.2 cos(2 angle), with `samples` points.
Mesh polygon_network(uint32_t n, uint32_t samples = 9);
// The same with corners at the given increasing angles (radians, from [0, 2 pi)): side k runs from
// corner k to corner k + 1 counter-clockwise, the last one back to corner 0.
Mesh polygon_network(const std::vector<double>& angles, uint32_t samples = 9);
// One face with n >= 3 sides whose loop turns at every corner: the corners as in polygon_network, each
// side the chord between them, lifted to z = 0.2 cos(2 angle) at its points' angles (polygon_network's
// arcs run straight on through the corners, and FIRE joins such sides, kStraightCornerTurn).
Mesh cornered_polygon_network(uint32_t n, uint32_t samples = 9);
Mesh cornered_polygon_network(const std::vector<double>& angles, uint32_t samples = 9);

// A grid of nx by ny square faces over [0, nx] x [0, ny], every curve on the surface z = height(x, y)
// with `samples` points; faces counter-clockwise seen from +z, numbered row by row (face j*nx + i).
// Horizontal edge (i, j) -> (i+1, j) is edge j*nx + i; vertical edge (i, j) -> (i, j+1) is edge
// (ny+1)*nx + j*(nx+1) + i.
Mesh grid_network(uint32_t nx, uint32_t ny, uint32_t samples, const Height& height);

// The network a control grid of 2m x 2m quads over [0, 2m]^2 (control point (i, j) lifted to
// height(i, j)) leaves when every second grid line is kept: m x m faces whose curves are the
// Catmull-Clark limit curves of the kept lines, sampled at the limit positions of their level-`levels`
// vertices (2^levels samples per control edge). Its FIRE base mesh has the control grid's topology.
Mesh limit_grid_network(uint32_t m, uint32_t levels, const Height& height);

// A curve across a random live face between two random points of its border, bowed up by a random height. Mostly between
// points inside two different edges; one in sixteen may end anywhere, which can make 2-sided faces.
EditCommand random_split(const Mesh& m, std::mt19937_64& rng);
// A stroke across 1 to 5 curves: from a random point of a random face's boundary, over random inner curves
// into the face beyond each, to a random point of the last face's boundary, each piece bowed up. The split
// system refuses the ones that cross at one place twice or whose pieces it cannot place.
std::optional<EditCommand> random_crossing(const Mesh& m, std::mt19937_64& rng);
// A stroke in pieces: a new pending chain from a random curve point up into the air, a piece more on a random
// chain, or a random chain finished by a split down to a random point of a face beside where it began.
std::optional<EditCommand> random_chain(const Mesh& m, std::mt19937_64& rng);
// A random change of topology: one time in three a random crossing stroke, one in three a random chain edit;
// else a random face made a hole
// (refused when it lies beside or touches the border), or a curve from a random border loop, bowed down: across
// its hole to another of its points, or to another border loop (a bridge, or the faces of a second one);
// nothing without faces.
std::optional<EditCommand> random_topology_edit(const Mesh& m, std::mt19937_64& rng);
// Deleting a random interior curve, or nothing when every curve is on the border.
std::optional<EditCommand> random_delete(const Mesh& m, std::mt19937_64& rng);
// One random edit through `history`, as the random-edit tests and the soak draw them: when `split`, a random
// topology edit one time in eight, else a random split; else by `dice`: a random delete below `delete_below`, an undo below `undo_below`, else a redo.
// Nothing (no edit made) when a delete was drawn and every curve is on the border.
std::optional<Status> random_edit(Mesh& net, EditHistory& history, std::mt19937_64& rng, bool split, uint64_t dice,
                                  uint64_t delete_below, uint64_t undo_below);

}  // namespace fire::test
