// 10,000 seeded random operations (splits, holes, curves across a border's hole, deletes, undos, redos) with
// validate() after each; a rejected
// operation must leave the pools untouched, and undo followed by redo must give the same pools back.
#include <random>

#include <catch2/catch.hpp>

#include "engine/network_io.hpp"
#include "tests/systems/reconstruct/networks.hpp"
#include "tests/engine/test_helpers.hpp"

using namespace fire;
using namespace fire::test;

namespace {

struct Stats {
  int splits = 0, topology = 0, deletes = 0, undos = 0, redos = 0, rejected = 0;
};


}  // namespace

TEST_CASE("10,000 random edits keep every invariant", "[random]") {
  std::mt19937_64 rng(20081124);
  EditHistory h;
  Mesh m = square(&h);
  Stats s;
  for (int step = 0; step < 10000; ++step) {
    uint64_t dice = rng() % 100;
    uint64_t before = m.hash();
    Status r;
    if (dice < 5) {
      const std::optional<EditCommand> c = random_topology_edit(m, rng);
      r = c ? h.apply(m, *c) : Status::failure("no face");
      s.topology += r.ok();
    } else if (dice < 55) {
      r = h.apply(m, random_split(m, rng, 8));
      s.splits += r.ok();
    } else if (dice < 70) {
      std::vector<EdgeIndex> interior;
      for (EdgeIndex e{0}; e < m.edge_slots(); ++e)
        if (m.edge_alive(e) && !m.is_border_edge(e)) interior.push_back(e);
      EditCommand del = make(EditKind::DeleteCurve);
      del.edge = interior.empty() ? EdgeIndex{0} : interior[rng() % interior.size()];
      r = h.apply(m, del);
      s.deletes += r.ok();
    } else if (dice < 88) {
      r = h.undo(m);
      s.undos += r.ok();
    } else {
      r = h.redo(m);
      s.redos += r.ok();
    }
    if (!r.ok()) {
      ++s.rejected;
      REQUIRE(m.hash() == before);
    }
    INFO("step " << step << ": " << r.error);
    REQUIRE(m.validate() == "");
    if (step % 500 == 0 && h.undo_depth() > 0) {
      Mesh snapshot = m;
      REQUIRE(h.undo(m).ok());
      REQUIRE(h.redo(m).ok());
      REQUIRE(m.same_pools(snapshot));
    }
  }
  // The mix really exercised every operation.
  CHECK(s.splits > 3000);
  CHECK(s.topology > 50);
  CHECK(s.deletes > 300);
  CHECK(s.undos > 1000);
  CHECK(s.redos > 150);
  CHECK(m.face_count() > 50);

  // The final network survives compaction and a round trip through the file format, exactly.
  m.compact();
  h.clear(m);
  REQUIRE(m.validate() == "");
  std::string text = network_to_json(m);
  auto back = network_from_json(text, "memory");
  REQUIRE(back.ok());
  CHECK(back->same_pools(m));
  CHECK(network_to_json(*back) == text);
}
