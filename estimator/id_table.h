// IdTable: the graph's variables and factors (graph.h) under their integer ids, in id order.
//
// A whole recording's graph holds 10^5-10^6 of each, added in id order; a tracking window adds at the back and erases
// mostly at the front. The elements sit in chunks of kChunk consecutive ids, so that a walk in id order reads memory
// in order and a look-up by id is an index (a std::map's walk chases a pointer per node, and its look-ups one per
// level). An element never moves while it is in the table: pointers and
// references to it stay valid until it is erased; iterators are invalidated by Add and Erase.
//
// A chunk is released once every id in it is erased: the table holds the chunks of its live elements only (a window
// with an element that never leaves, such as tracking's calibration prior, holds that element's chunk and the
// window's).
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <iterator>
#include <memory>
#include <optional>
#include <type_traits>
#include <utility>

#include "common/check.h"

namespace roamlab::estimator {

template <typename T>
class IdTable {
 public:
  using Id = std::int64_t;
  using value_type = std::pair<const Id, T>;
  static constexpr int kChunk = 256;

 private:
  struct Chunk {
    explicit Chunk(Id first_id) : first(first_id) {}
    Id first;  // the id of slots[0], a multiple of kChunk
    std::array<std::optional<value_type>, kChunk> slots;
    int live = 0;
  };

 public:
  // Bidirectional, in id order, over the elements present (as a std::map's).
  template <bool kConst>
  class Iterator {
   public:
    using iterator_category = std::bidirectional_iterator_tag;
    using value_type = IdTable::value_type;
    using difference_type = std::ptrdiff_t;
    using pointer = std::conditional_t<kConst, const value_type*, value_type*>;
    using reference = std::conditional_t<kConst, const value_type&, value_type&>;
    using Table = std::conditional_t<kConst, const IdTable, IdTable>;

    Iterator() = default;
    Iterator(Table* table, std::size_t chunk, int slot) : table_(table), chunk_(chunk), slot_(slot) {}
    operator Iterator<true>() const { return Iterator<true>(table_, chunk_, slot_); }  // NOLINT: as std's iterators

    reference operator*() const { return *table_->chunks_[chunk_]->slots[slot_]; }
    pointer operator->() const { return &**this; }
    Iterator& operator++() {
      ++slot_;
      SkipForward();
      return *this;
    }
    Iterator& operator--() {
      // (Never before begin(), as for any bidirectional iterator.)
      do {
        if (slot_ == 0) {
          --chunk_;
          slot_ = kChunk;
        }
        --slot_;
      } while (!table_->chunks_[chunk_]->slots[slot_]);
      return *this;
    }
    Iterator operator++(int) {
      Iterator before = *this;
      ++*this;
      return before;
    }
    Iterator operator--(int) {
      Iterator before = *this;
      --*this;
      return before;
    }
    bool operator==(const Iterator& other) const { return chunk_ == other.chunk_ && slot_ == other.slot_; }
    bool operator!=(const Iterator& other) const { return !(*this == other); }

   private:
    friend class IdTable;
    // From (chunk_, slot_) on to the first element present, or end().
    void SkipForward() {
      const auto& chunks = table_->chunks_;
      while (chunk_ < chunks.size()) {
        const auto& slots = chunks[chunk_]->slots;
        while (slot_ < kChunk && !slots[slot_]) ++slot_;
        if (slot_ < kChunk) return;
        ++chunk_;
        slot_ = 0;
      }
    }

    Table* table_ = nullptr;
    std::size_t chunk_ = 0;
    int slot_ = 0;
  };
  using iterator = Iterator<false>;
  using const_iterator = Iterator<true>;
  using const_reverse_iterator = std::reverse_iterator<const_iterator>;

  IdTable() = default;
  IdTable(const IdTable&) = delete;
  IdTable& operator=(const IdTable&) = delete;
  IdTable(IdTable&&) = default;
  IdTable& operator=(IdTable&&) = default;

  // Adds `value` under `id`, which must be greater than every id added before.
  T& Add(Id id, T value) {
    ROAMLAB_CHECK(id >= next_, "id " << id << " added after " << next_ - 1);
    next_ = id + 1;
    const Id first = FirstOfChunk(id);
    if (chunks_.empty() || chunks_.back()->first != first) chunks_.push_back(std::make_unique<Chunk>(first));
    Chunk& chunk = *chunks_.back();
    std::optional<value_type>& slot = chunk.slots[id - first];
    slot.emplace(id, std::move(value));
    ++chunk.live;
    ++size_;
    return slot->second;
  }

  // Erases the element under `id` (which must be present).
  void Erase(Id id) {
    const std::size_t c = ChunkOf(id);
    ROAMLAB_CHECK(c < chunks_.size() && chunks_[c]->slots[id - chunks_[c]->first], "no element " << id);
    chunks_[c]->slots[id - chunks_[c]->first].reset();
    --size_;
    if (--chunks_[c]->live == 0) chunks_.erase(chunks_.begin() + static_cast<std::ptrdiff_t>(c));
  }

  // The element under `id`, or null.
  T* Find(Id id) {
    const std::size_t c = ChunkOf(id);
    if (c == chunks_.size()) return nullptr;
    std::optional<value_type>& slot = chunks_[c]->slots[id - chunks_[c]->first];
    return slot ? &slot->second : nullptr;
  }
  const T* Find(Id id) const { return const_cast<IdTable*>(this)->Find(id); }
  std::size_t count(Id id) const { return Find(id) != nullptr ? 1 : 0; }

  std::size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }

  iterator begin() { return First<false>(this, 0, 0); }
  iterator end() { return iterator(this, chunks_.size(), 0); }
  const_iterator begin() const { return First<true>(this, 0, 0); }
  const_iterator end() const { return const_iterator(this, chunks_.size(), 0); }
  const_reverse_iterator rbegin() const { return const_reverse_iterator(end()); }
  const_reverse_iterator rend() const { return const_reverse_iterator(begin()); }
  // The first element with an id not less than `id`.
  const_iterator lower_bound(Id id) const {
    const Id first = FirstOfChunk(id);
    const auto chunk =
        std::lower_bound(chunks_.begin(), chunks_.end(), first, [](const auto& c, Id key) { return c->first < key; });
    const int slot = chunk != chunks_.end() && (*chunk)->first == first ? static_cast<int>(id - first) : 0;
    return First<true>(this, static_cast<std::size_t>(chunk - chunks_.begin()), slot);
  }

 private:
  static Id FirstOfChunk(Id id) { return id - ((id % kChunk) + kChunk) % kChunk; }
  // The place in chunks_ of the chunk holding `id`, or chunks_.size(): the place its first id would have without
  // released chunks before it (a table that only grew), else a binary search.
  std::size_t ChunkOf(Id id) const {
    if (chunks_.empty()) return 0;
    const Id first = FirstOfChunk(id);
    const Id guess = (first - chunks_.front()->first) / kChunk;
    if (guess >= 0 && guess < static_cast<Id>(chunks_.size()) && chunks_[guess]->first == first)
      return static_cast<std::size_t>(guess);
    const auto chunk =
        std::lower_bound(chunks_.begin(), chunks_.end(), first, [](const auto& c, Id key) { return c->first < key; });
    return chunk != chunks_.end() && (*chunk)->first == first ? static_cast<std::size_t>(chunk - chunks_.begin())
                                                              : chunks_.size();
  }
  template <bool kConst, typename Table>
  static Iterator<kConst> First(Table* table, std::size_t chunk, int slot) {
    Iterator<kConst> it(table, chunk, slot);
    it.SkipForward();
    return it;
  }

  std::deque<std::unique_ptr<Chunk>> chunks_;  // the chunks with live elements, in id order
  Id next_ = 0;                                // ids below it have been added
  std::size_t size_ = 0;
};

}  // namespace roamlab::estimator
