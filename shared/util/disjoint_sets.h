#pragma once
// Union-find over the integers 0..n-1 with path halving: which elements have been joined.

#include <algorithm>
#include <cstddef>
#include <numeric>
#include <vector>

namespace silnet {

// Disjoint sets of 0..n-1, each element alone at first. Find returns the same representative
// for two elements iff a chain of Union calls joined them; the representative of a set is its
// smallest element.
class DisjointSets {
 public:
  explicit DisjointSets(size_t n) : parent_(n) { std::iota(parent_.begin(), parent_.end(), 0); }
  size_t Find(size_t x) {
    while (parent_[x] != x) {
      parent_[x] = parent_[parent_[x]];
      x = parent_[x];
    }
    return x;
  }
  void Union(size_t a, size_t b) {
    a = Find(a);
    b = Find(b);
    if (a != b) parent_[std::max(a, b)] = std::min(a, b);
  }

 private:
  std::vector<size_t> parent_;
};

}  // namespace silnet
