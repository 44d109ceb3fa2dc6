#pragma once
// Per-frame element indices: a pool slot typed by its kind, so an edge cannot be passed where a face is asked
// for, nor a bare number where either is. Made from a number explicitly (`EdgeIndex{e}`), read as one
// implicitly (column subscripts, comparisons with kNone, arithmetic). An index names a slot for the frame it
// was read in; what must outlive the frame holds a Handle with its generation (mesh.hpp).
#include <cstdint>
#include <type_traits>

#include "engine/common.hpp"

namespace fire {

template <class Tag>
struct Index {
  uint32_t value = kNone;
  constexpr Index() = default;
  constexpr explicit Index(uint32_t v) : value(v) {}
  constexpr operator uint32_t() const { return value; }
  // The next slot, for loops over a pool's slots.
  constexpr Index& operator++() {
    ++value;
    return *this;
  }
};

using VertexIndex = Index<struct VertexTag>;
using EdgeIndex = Index<struct EdgeTag>;
using FaceIndex = Index<struct FaceTag>;
// An edge as a face loop walks it: edge << 1 | reversed.
using OrientedEdge = Index<struct OrientedEdgeTag>;

// Columns hold indices and snapshots write them by bytes: an index is exactly its number.
static_assert(sizeof(OrientedEdge) == sizeof(uint32_t) && std::is_trivially_copyable_v<OrientedEdge>);

template <class T>
inline constexpr bool kIsIndex = false;
template <class Tag>
inline constexpr bool kIsIndex<Index<Tag>> = true;

}  // namespace fire
