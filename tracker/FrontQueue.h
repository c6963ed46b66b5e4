// The breadth-first traversal's queue, as a ring buffer. A surfel stays in the queue only
// between being reached and being processed, so the queue holds the traversal front: about
// the perimeter of the part of the surface already visited (O(q) surfels on a q^3 image), not
// the surface. Its memory stays small and in cache instead of growing with every surfel.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace surftrack {

template <class T>
class FrontQueue {
 public:
  FrontQueue() : ring_(1024), mask_(1023) {}

  bool empty() const { return head_ == tail_; }

  void push(T value) {
    if (tail_ - head_ == ring_.size()) [[unlikely]] grow();
    ring_[tail_++ & mask_] = value;
  }

  /// Makes room for n more values, for pushIf.
  void reserve(std::size_t n) {
    while (tail_ - head_ + n > ring_.size()) [[unlikely]] grow();
  }
  /// Appends `value` if `keep`, without a branch (whether a surfel is new is unpredictable).
  void pushIf(T value, bool keep) {
    ring_[tail_ & mask_] = value;
    tail_ += keep;
  }

  T pop() { return ring_[head_++ & mask_]; }

  /// Values pushed so far.
  std::size_t pushed() const { return tail_; }

 private:
  void grow() {
    std::vector<T> bigger(2 * ring_.size());
    for (std::size_t i = head_; i != tail_; ++i) bigger[i & (bigger.size() - 1)] = ring_[i & mask_];
    ring_.swap(bigger);
    mask_ = ring_.size() - 1;
  }

  std::vector<T> ring_;
  std::size_t mask_;
  std::size_t head_ = 0, tail_ = 0;
};

}  // namespace surftrack
