// A std::vector filled through a raw pointer. The tracker appends a few values per surfel to
// each of its arrays; checking capacity once per surfel (reserve) instead of on every append
// keeps the hot loop to a store and an increment. take() hands the vector over without a copy.
#pragma once

#include <algorithm>
#include <cstddef>
#include <utility>
#include <vector>

namespace surftrack {

template <class T>
class AppendBuffer {
 public:
  explicit AppendBuffer(std::size_t capacity = 4096) : data_(std::max<std::size_t>(capacity, 1)) {
    next_ = data_.data();
    end_ = next_ + data_.size();
  }

  /// Makes room for n more values.
  void reserve(std::size_t n) {
    if (std::size_t(end_ - next_) < n) [[unlikely]] grow(n);
  }
  /// Appends; room must have been made.
  void push(T value) { *next_++ = value; }

  std::size_t size() const { return std::size_t(next_ - data_.data()); }
  T& operator[](std::size_t i) { return data_[i]; }
  const T& operator[](std::size_t i) const { return data_[i]; }

  std::vector<T> take() && {
    data_.resize(size());
    return std::move(data_);
  }

 private:
  void grow(std::size_t n) {
    const std::size_t used = size();
    data_.resize(std::max(2 * data_.size(), used + n));
    next_ = data_.data() + used;
    end_ = data_.data() + data_.size();
  }

  std::vector<T> data_;
  T* next_;
  T* end_;
};

}  // namespace surftrack
