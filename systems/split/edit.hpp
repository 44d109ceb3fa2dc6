#pragma once
// The editing operations a person performs while drawing (thesis 5.4): the border polygon, face
// splitting by a new curve, deleting a curve, marking a curve sharp (or smooth again), and undo/redo of all of them.
//
// Every operation checks its whole input before it changes anything: a rejected command leaves the
// pools exactly as they were and says why.
#include <vector>

#include "engine/edit_command.hpp"
#include "engine/mesh.hpp"

namespace fire {

// Runs one command on the mesh (no history). Border rules: StartBorder needs no border polygon open (on a
// mesh with faces it starts a new part); AppendBorder starts the new edge at the last vertex of the open
// border (its first point is moved there, as thesis 5.4.1 prescribes); CloseBorder adds the last edge, whose
// last point must lie within snap_distance of the first vertex, and creates the part's first face. SplitFace
// and DeleteCurve need a closed border. ToggleSharp flips an inner curve's sharp flag (a crease of the
// surface); border curves are creases already and are refused. MakeHole removes a face that touches no border
// (its curves become border). SplitHole draws a curve across the hole of one border loop, the far side of the
// surface there: the hole becomes two faces, one each side of the curve, and that border is gone. JoinBorders
// draws a curve from one border loop to another across the hole between them (a handle, a vessel's wall, two
// parts joined): the first is a bridge, with no face, and the second between the same two loops turns the hole
// between them into two faces. DeleteCurve removes a bridge still waiting. CrossCurves draws a stroke over
// several faces: every curve it crosses, and the curves its ends lie on, are cut there, and each piece splits
// the face it runs over, in one transaction (one undo); refused when a crossing is on the border, when two
// cuts are at one place, or when two pieces cross in one face.
Status execute_edit(Mesh& mesh, const EditCommand& command);

// Splits edge e at interior polyline point `point` (0 < point < count-1): a new vertex and two edges
// replace e in every face that uses it. Returns the new vertex. Exposed for tools and tests.
VertexIndex split_edge(Mesh& mesh, EdgeIndex e, uint32_t point);

// Undo by journal rollback (bit-identical pools); redo by running the command again, which is
// deterministic from the restored state.
class EditHistory {
 public:
  Status apply(Mesh& mesh, const EditCommand& command);
  Status undo(Mesh& mesh);
  Status redo(Mesh& mesh);
  size_t undo_depth() const { return undo_.size(); }
  size_t redo_depth() const { return redo_.size(); }
  // The newest command on the undo stack that drew a curve (a border or split kind); nullptr when none:
  // what "the curve drawn last" means to a command that has no cursor to pick with (the command pad).
  const EditCommand* last_drawn() const;
  // The newest command on the undo stack; nullptr when none.
  const EditCommand* last_applied() const { return undo_.empty() ? nullptr : &undo_.back().command; }
  // Forgets everything (needed after Mesh::compact, which cannot be undone).
  void clear(Mesh& mesh);
  // A snapshot of the history (engine/SESSION.md): each undoable command with its marks into the
  // mesh's journals, and the redo commands. load() needs the mesh loaded from the same snapshot and
  // fails on marks its journals cannot hold.
  void save(SnapshotWriter& out) const;
  bool load(SnapshotReader& in, const Mesh& mesh);

 private:
  Status run(Mesh& mesh, const EditCommand& command);
  struct Entry {
    EditCommand command;
    MeshMark mark;
  };
  std::vector<Entry> undo_;
  std::vector<EditCommand> redo_;
};

}  // namespace fire
