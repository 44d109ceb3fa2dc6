#pragma once
// A struct's fields listed once, in the order they lie in a snapshot, and walked by SnapshotPut to write them
// and by SnapshotGet to read them back, so that saving and loading cannot drift apart. A field list is a
// template over the walker and the struct (const when writing):
//   template <class Io, class S> void fields(Io& io, S& s) { io(s.count); io.flag(s.open); ... }
#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <optional>

#include "engine/session_dir.hpp"

namespace fire {

struct SnapshotPut {
  SnapshotWriter& out;
  template <class T>
  void operator()(const T& v) {
    out.put(v);
  }
  template <int N>
  void operator()(const Eigen::Matrix<double, N, 1>& p) {
    for (int k = 0; k < N; ++k) out.put(p[k]);
  }
  template <class T, size_t N>
  void operator()(const std::array<T, N>& a) {
    for (const T& x : a) (*this)(x);
  }
  // Counts are size_t in memory and u64 on disk, so a snapshot reads the same on any build.
  template <class T>
  void count(const T& n) {
    out.put(uint64_t(n));
  }
  void flag(bool b) { out.put(uint8_t(b)); }
  // A value held on disk as `Disk`.
  template <class Disk, class T>
  void as(const T& v) {
    out.put(Disk(v));
  }
  // A sequence as its count and its elements, each walked by `one`.
  template <class Seq, class One>
  void sequence(const Seq& s, One one) {
    count(s.size());
    for (const auto& x : s) one(x);
  }
  // An optional value as a flag and, when it is there, the value walked by `one`.
  template <class T, class One>
  void optional(const std::optional<T>& o, One one) {
    flag(o.has_value());
    if (o) one(*o);
  }
  // A struct with its own save and load.
  template <class T>
  void object(const T& x) {
    x.save(out);
  }
  // Fields added later behind a record byte: written always; a snapshot from before ends above them.
  template <class Fields>
  void since(uint8_t record, Fields fields) {
    out.put(record);
    fields();
  }
  // What a read must find true: nothing to check when writing.
  void check(bool) {}
};

struct SnapshotGet {
  SnapshotReader& in;
  template <class T>
  void operator()(T& v) {
    in.get(v);
  }
  template <int N>
  void operator()(Eigen::Matrix<double, N, 1>& p) {
    for (int k = 0; k < N; ++k) in.get(p[k]);
  }
  template <class T, size_t N>
  void operator()(std::array<T, N>& a) {
    for (T& x : a) (*this)(x);
  }
  template <class T>
  void count(T& n) {
    uint64_t v = 0;
    in.get(v);
    n = T(v);
  }
  void flag(bool& b) {
    uint8_t v = 0;
    in.get(v);
    if (v > 1) in.fail();
    b = v != 0;
  }
  template <class Disk, class T>
  void as(T& v) {
    Disk d{};
    in.get(d);
    v = T(d);
  }
  template <class Seq, class One>
  void sequence(Seq& s, One one) {
    uint64_t n = 0;
    in.get(n);
    s.clear();
    for (uint64_t k = 0; k < n && in.ok(); ++k) one(s.emplace_back());
  }
  template <class T, class One>
  void optional(std::optional<T>& o, One one) {
    bool has = false;
    flag(has);
    o.reset();
    if (has) one(o.emplace());
  }
  template <class T>
  void object(T& x) {
    if (!x.load(in)) in.fail();
  }
  template <class Fields>
  void since(uint8_t record, Fields fields) {
    if (!in.ok() || in.at_end()) return;
    uint8_t found = 0;
    in.get(found);
    check(found == record);
    fields();
  }
  void check(bool holds) {
    if (!holds) in.fail();
  }
};

}  // namespace fire
