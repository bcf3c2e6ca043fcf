#pragma once
/// \file Child order: in which order a traversal enters the children of a node it descends.
///
/// Sorted tests all children of an entered node, then enters those hit nearest-first and stops
/// as soon as the next entry lies beyond the closest hit (the paper's "examine the bounding
/// volumes in sorted order"); stored order enters each child as soon as its test succeeds, in
/// the order the hierarchy stores them (the paper's unsorted traversal).

namespace amalgam {

struct SortedOrder {
  static constexpr bool kSorted = true;
};

struct StoredOrder {
  static constexpr bool kSorted = false;
};

}  // namespace amalgam
