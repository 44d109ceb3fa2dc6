#pragma once
// One array of a structure-of-arrays pool, with an undo journal.
//
// While a transaction is open, every write to a slot that existed when it began records the old value;
// growth needs no record because undo truncates back to the size at the start. Undo therefore restores
// the column bit for bit, and redo is re-running the (deterministic) operation.
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include "engine/assert.hpp"

namespace fire {

struct ColumnMark {
  uint32_t size = 0;
  uint32_t journal = 0;
};

template <class T>
class Column {
 public:
  size_t size() const { return data_.size(); }
  bool empty() const { return data_.empty(); }
  const T& operator[](size_t i) const { return data_[i]; }
  std::span<const T> span() const { return data_; }
  std::span<const T> span(size_t offset, size_t count) const { return std::span<const T>(data_).subspan(offset, count); }
  const std::vector<T>& values() const { return data_; }
  // What undo can still restore: (slot, old value) pairs in the order they were recorded.
  const std::vector<std::pair<uint32_t, T>>& journal() const { return journal_; }

  void set(size_t i, const T& v) {
    if (recording_ && i < base_size_) journal_.emplace_back(static_cast<uint32_t>(i), data_[i]);
    data_[i] = v;
  }
  void push_back(const T& v) { data_.push_back(v); }
  void pop_back() {
    if (recording_ && data_.size() - 1 < base_size_) journal_.emplace_back(static_cast<uint32_t>(data_.size() - 1), data_.back());
    data_.pop_back();
  }
  void assign(std::vector<T> v) {
    FIRE_ASSERT(!recording_, "assign replaces the whole column, which a transaction cannot undo");
    data_ = std::move(v);
  }
  // Replaces values and journal with those a snapshot recorded (outside a transaction).
  void restore(std::vector<T> data, std::vector<std::pair<uint32_t, T>> journal) {
    FIRE_ASSERT(!recording_, "a snapshot is loaded between frames, never inside a transaction");
    data_ = std::move(data);
    journal_ = std::move(journal);
  }
  void reserve(size_t n) { data_.reserve(n); }
  void clear() { data_.clear(); journal_.clear(); }

  ColumnMark begin() {
    recording_ = true;
    base_size_ = static_cast<uint32_t>(data_.size());
    return {base_size_, static_cast<uint32_t>(journal_.size())};
  }
  void end() { recording_ = false; }
  // Restores the state at `mark`, which must be the most recent mark not yet rolled back, and tells
  // `restored(begin, end)` every slot range it rewrote or removed, so change stamps mark exactly those.
  template <class OnRestore>
  void rollback(const ColumnMark& mark, OnRestore&& restored) {
    FIRE_ASSERT(mark.journal <= journal_.size(), "rollback to a mark that was already rolled back");
    if (data_.size() > mark.size) restored(mark.size, static_cast<uint32_t>(data_.size()));
    data_.resize(mark.size);
    while (journal_.size() > mark.journal) {
      auto& [i, old] = journal_.back();
      if (i < data_.size()) {
        data_[i] = old;
        restored(i, i + 1);
      }
      journal_.pop_back();
    }
  }
  // Whether anything was written, grown or shrunk since `mark`.
  bool changed_since(const ColumnMark& mark) const { return data_.size() != mark.size || journal_.size() != mark.journal; }
  // History older than this point can no longer be undone (after compaction, or when trimming history).
  void forget_journal() { journal_.clear(); }
  size_t journal_bytes() const { return journal_.capacity() * sizeof(std::pair<uint32_t, T>); }
  size_t bytes() const { return data_.capacity() * sizeof(T); }

 private:
  std::vector<T> data_;
  std::vector<std::pair<uint32_t, T>> journal_;
  uint32_t base_size_ = 0;
  bool recording_ = false;
};

}  // namespace fire
