// Exact nearest-neighbour queries over a fixed 3D point set: a balanced kd-tree (median splits on the
// widest side of each node's box, all leaves at one depth with at most 8 points), each node with the tight
// bounding box of its points (floats rounded outwards), the points stored in leaf order.
//
// One answer per query, whatever the build or the thread count: points are ordered by (squared distance,
// index), the squared distance being (qx-px)^2 + (qy-py)^2 + (qz-pz)^2 summed in that order in double (the
// same numbers as CGAL's Euclidean_distance, so results such as average_spacing() stay bit for bit what
// the CGAL kd-tree gave). A node is skipped only when its box is strictly farther than the current k-th
// candidate, so ties at the k-th place go to the smaller index.
// Queries are const and thread-safe; the build runs its halves in parallel (TBB) and is deterministic.
#pragma once

#include "core/types.h"

#include <cstdint>
#include <vector>

namespace hsr {

class KdTree {
 public:
  KdTree() = default;
  explicit KdTree(const std::vector<Vec3>& points);

  std::size_t size() const { return slots_.size(); }

  /// The min(k, size()) nearest points to q, nearest first: their indices into `index` and, when `d2` is
  /// not null, their squared distances. Returns how many were written.
  int nearest_k(const Vec3& q, int k, int* index, double* d2 = nullptr) const;

  /// Index of the nearest point (smallest index among equidistant ones); its squared distance into `d2`.
  /// Requires size() > 0.
  int nearest(const Vec3& q, double* d2 = nullptr) const;

  /// Input indices in leaf order (neighbours in space are neighbours here): a cache-friendly query order.
  std::vector<int> leaf_order() const;

  /// The k nearest neighbours of every point of the tree, as nearest_k would give them for each, with the
  /// point itself left out: row i (k entries, row-major, size() * k in all) holds the first k of the k + 1
  /// nearest to point i once i is removed from them. Requires 0 < k < size(). The queries of one leaf share
  /// one walk of the tree (their common box is the bound), leaves run in parallel; deterministic.
  std::vector<int> neighbour_rows(int k) const;

 private:
  struct Slot {
    double x, y, z;
    int index;
  };
  struct Box {
    float lo[3], hi[3];
  };
  std::size_t first_leaf() const { return (std::size_t(1) << depth_) - 1; }

  std::vector<Slot> slots_;            ///< the points in leaf order
  std::vector<Box> boxes_;             ///< per node (implicit heap layout: children 2i+1, 2i+2; leaves last)
  std::vector<std::uint32_t> leaf_start_;  ///< slot range of leaf j: [leaf_start_[j], leaf_start_[j + 1])
  int depth_ = 0;                      ///< every leaf is at this depth
};

/// Groups of `subset` (indices into `points`) whose members come closer than `link` to each other (each point
/// linked with those of its 16 nearest in the subset within `link`: enough to link every point of a surface
/// sampled at its spacing), each in subset order, the groups in order of their first member (`subset` ascending:
/// each sorted, by smallest index). Deterministic.
std::vector<std::vector<int>> linked_groups(const std::vector<Vec3>& points, const std::vector<int>& subset,
                                            double link);

}  // namespace hsr
