// Which labels a label scan converts (internal to core/), shared by the single pass
// (Labels.cpp) and the block scan (LabelBlocks.cpp): the checks of a selection that need no
// scan, and the test the scan applies to each value it meets.
#pragma once

#include <algorithm>
#include <vector>

#include "Errors.h"
#include "Labels.h"
#include "SelectionValue.h"

namespace surftrack {

/// A list selection's labels are values of the type other than the background.
template <class T>
void requireListable(const LabelSelection& selection, const LabelValue& background) {
  if (selection.labels.empty()) throw InvalidInput("empty selection: the list of labels is empty");
  for (const LabelValue& L : selection.labels) {
    requireSelectable(scalarTypeOf<T>(), Selection::label(L));
    if (L == background) throw InvalidInput("label " + L.text() + " is the background");
  }
}

inline void requireNonEmptyRange(const LabelSelection& selection) {
  if (selection.first > selection.last)
    throw InvalidInput("label range [" + selection.first.text() + ", " + selection.last.text() + "] is empty");
}

/// Whether the scan converts label L (the selection checked by requireListable /
/// requireNonEmptyRange; the single pass's selectLabels then reports the listed labels that do
/// not occur, which a block cannot know).
template <class T>
struct WantedLabel {
  const LabelSelection& selection;
  std::vector<T> listed;  ///< List: sorted
  explicit WantedLabel(const LabelSelection& s) : selection(s) {
    if (s.kind == LabelSelection::Kind::List) {
      for (const LabelValue& L : s.labels) listed.push_back(L.as<T>());
      std::sort(listed.begin(), listed.end());
    }
  }
  bool operator()(T L) const {
    switch (selection.kind) {
      case LabelSelection::Kind::List: return std::binary_search(listed.begin(), listed.end(), L);
      case LabelSelection::Kind::Range: return LabelValue(L) >= selection.first && LabelValue(L) <= selection.last;
      default: return true;
    }
  }
};

}  // namespace surftrack
