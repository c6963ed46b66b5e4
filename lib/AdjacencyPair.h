// The four adjacency pairs (kappa, lambda) of paper §5 for which beta^{kappa lambda} gives
// Jordan triples (Proposition 39): kappa connects 1-voxels, lambda connects 0-voxels.
#pragma once

#include <array>
#include <stdexcept>
#include <string>
#include <string_view>

namespace surftrack {

enum class AdjacencyPair { k26_6, k18_6, k6_18, k6_26 };

inline constexpr std::array<AdjacencyPair, 4> kAllAdjacencyPairs = {
    AdjacencyPair::k26_6, AdjacencyPair::k18_6, AdjacencyPair::k6_18, AdjacencyPair::k6_26};

constexpr int kappa(AdjacencyPair p) {
  return p == AdjacencyPair::k26_6 ? 26 : p == AdjacencyPair::k18_6 ? 18 : 6;
}
constexpr int lambda(AdjacencyPair p) {
  return p == AdjacencyPair::k6_18 ? 18 : p == AdjacencyPair::k6_26 ? 26 : 6;
}

/// "26-6", "18-6", "6-18", "6-26".
inline std::string toString(AdjacencyPair p) {
  return std::to_string(kappa(p)) + "-" + std::to_string(lambda(p));
}

/// Parses "26-6", "26,6" or "(26,6)"; throws std::invalid_argument for anything else.
inline AdjacencyPair parseAdjacencyPair(std::string_view text) {
  std::string s;
  for (char ch : text)
    if (ch != '(' && ch != ')' && ch != ' ') s += (ch == ',' ? '-' : ch);
  for (AdjacencyPair p : kAllAdjacencyPairs)
    if (toString(p) == s) return p;
  throw std::invalid_argument("unsupported adjacency pair '" + std::string(text) +
                              "': expected one of 26-6, 18-6, 6-18, 6-26");
}

}  // namespace surftrack
