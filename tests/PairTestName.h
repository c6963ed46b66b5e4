// The name of a test instantiated once per adjacency pair ("k26_6", ...), for gtest's
// INSTANTIATE_TEST_SUITE_P, and how gtest prints such a parameter ("26-6", not its bytes). The
// names come from a table: built by string concatenation they trip a false -Wrestrict warning in
// GCC 12's <string>.
#pragma once

#include <gtest/gtest.h>

#include <ostream>
#include <string>

#include "AdjacencyPair.h"

namespace surftrack {
inline void PrintTo(AdjacencyPair pair, std::ostream* os) { *os << toString(pair); }
}  // namespace surftrack

namespace surftrack::testing {

inline std::string pairTestName(const ::testing::TestParamInfo<AdjacencyPair>& info) {
  static const char* const kNames[] = {"k26_6", "k18_6", "k6_18", "k6_26"};
  return kNames[static_cast<int>(info.param)];
}

}  // namespace surftrack::testing
