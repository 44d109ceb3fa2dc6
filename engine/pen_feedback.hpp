#pragma once
// What the pen would do if it went down or up now, published by the sketch system every frame for the
// renderer (which lives in platform/ and never calls a system): the point a stroke end at the pen would snap
// to, the face the pen is over, and in border mode whether a stroke ending here closes the border at its
// first vertex. Elements are named by handles with their generation, so a reader checks they still exist.
// Derived from the input log like the pools, but shown only: it is no part of world_hash nor of snapshots.
#include "engine/mesh.hpp"

namespace fire {

struct PenFeedback {
  bool pen_seen = false;  // a pen sample has arrived since the last pen up; nothing below means anything before
  bool pen_down = false;
  Vec3 pen = Vec3::Zero();  // the last pen sample
  double radius = 0;        // the snap radius at that sample (model units)
  // Where a stroke end at the pen snaps: a polyline point of an edge, or (closes_border) the first vertex.
  EdgeId target_edge;
  uint32_t target_point = 0;
  Vec3 target = Vec3::Zero();
  // Split mode: the face the pen is over; while drawing, the face the stroke would split if it ended here.
  FaceId face;
  // Border mode: the border's first vertex, and whether a stroke ending at the pen would close the border.
  VertexId first_vertex;
  bool closes_border = false;

  bool has_target() const { return target_edge.valid() || closes_border; }
};

}  // namespace fire
