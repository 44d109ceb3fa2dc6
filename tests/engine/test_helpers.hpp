#pragma once
// Tiny hand-made networks for the engine tests.
#include <random>
#include <vector>

#include "engine/mesh.hpp"
#include "systems/split/edit.hpp"

namespace fire::test {

// Straight polyline from a to b with n points.
std::vector<Vec3> line(const Vec3& a, const Vec3& b, int n = 5);

// A closed square border 0..1 in the xy plane drawn as 4 edges of 5 points each (one face).
Mesh square(EditHistory* history = nullptr);

// A command of `kind` with these curve points (the other fields default).
EditCommand make(EditKind kind, std::vector<Vec3> points = {});
// The helpers take slots as plain numbers, as the tests write them for their tiny meshes (typed indices read as
// numbers too).
// Delete edge e.
EditCommand remove(uint32_t e);
EditCommand split(uint32_t face, CurveEnd a, CurveEnd b, const std::vector<Vec3>& points);
// A curve end written as {edge slot, point}.
struct SlotEnd {
  uint32_t edge, point;
};
EditCommand split(uint32_t face, SlotEnd a, SlotEnd b, const std::vector<Vec3>& points);
// The point of edge e's polyline at index k.
Vec3 at(const Mesh& m, uint32_t e, uint32_t k);
// Faces' loop sizes, sorted.
std::vector<uint32_t> face_sizes(const Mesh& m);
// The live edge joining vertices a and b, or kNone.
EdgeIndex edge_between(const Mesh& m, uint32_t a, uint32_t b);
// A split of a random live face between two random points of its border (possibly the same edge or point,
// so some are rejected), with 2 to max_points - 1 points lifted up to 0.1 out of the plane.
EditCommand random_split(const Mesh& m, std::mt19937_64& rng, int max_points);

}  // namespace fire::test
