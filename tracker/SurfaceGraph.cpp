#include "SurfaceGraph.h"

#include <iterator>
#include <utility>

namespace surftrack {
namespace {

// Walks the (source, target) pairs of a CSR structure in source order, which is what Boost's
// edges_are_sorted constructor expects; it avoids materialising an edge list.
class CsrArcIterator {
 public:
  using iterator_category = std::input_iterator_tag;
  using value_type = std::pair<std::uint32_t, std::uint32_t>;
  using difference_type = std::ptrdiff_t;
  using pointer = const value_type*;
  using reference = const value_type&;

  CsrArcIterator(const std::vector<std::uint32_t>& rowStart,
                 const std::vector<std::uint32_t>& targets, std::size_t arc)
      : rowStart_(&rowStart), targets_(&targets), arc_(arc) {
    settle();
  }
  const value_type& operator*() const { return current_; }
  const value_type* operator->() const { return &current_; }
  CsrArcIterator& operator++() {
    ++arc_;
    settle();
    return *this;
  }
  CsrArcIterator operator++(int) {
    CsrArcIterator old = *this;
    ++*this;
    return old;
  }
  bool operator==(const CsrArcIterator& o) const { return arc_ == o.arc_; }
  bool operator!=(const CsrArcIterator& o) const { return arc_ != o.arc_; }

 private:
  void settle() {
    while (source_ + 1 < rowStart_->size() && (*rowStart_)[source_ + 1] <= arc_) ++source_;
    if (arc_ < targets_->size()) current_ = {source_, (*targets_)[arc_]};
  }
  const std::vector<std::uint32_t>* rowStart_;
  const std::vector<std::uint32_t>* targets_;
  std::size_t arc_;
  std::uint32_t source_ = 0;
  value_type current_{};
};

}  // namespace

SurfelGraph makeSurfelGraph(const std::vector<std::uint32_t>& rowStart,
                            const std::vector<std::uint32_t>& targets) {
  const std::uint32_t vertices = rowStart.empty() ? 0 : std::uint32_t(rowStart.size() - 1);
  return SurfelGraph(boost::edges_are_sorted, CsrArcIterator(rowStart, targets, 0),
                     CsrArcIterator(rowStart, targets, targets.size()), vertices);
}

}  // namespace surftrack
