// Stage 1, normals of a cloud that has none (DESIGN.md "Normals"): PCA on each point's kNN row, oriented
// along a minimum spanning tree (the algorithm of CGAL's mst_orient_normals), both parallel (TBB) and
// deterministic whatever the thread count.
#include "structure/structure_internal.h"

#include <Eigen/Eigenvalues>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <numeric>

namespace hsr::structure_detail {

// PCA normal of each point from its kNN row (plus itself).
std::vector<Vec3> estimate_normals(const std::vector<Vec3>& pts, const KnnGraph& g, int k) {
  const int kk = std::min(k, g.k);
  std::vector<Vec3> normals(pts.size());
  tbb::parallel_for(std::size_t(0), pts.size(), [&](std::size_t i) {
    const int* row = g.row(i);
    Vec3 c = pts[i];
    for (int j = 0; j < kk; ++j) c += pts[row[j]];
    c /= (kk + 1);
    Eigen::Matrix3d cov = (pts[i] - c) * (pts[i] - c).transpose();
    for (int j = 0; j < kk; ++j) {
      const Vec3 d = pts[row[j]] - c;
      cov += d * d.transpose();
    }
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(cov);
    Vec3 n = es.eigenvectors().col(0);
    if (!std::isfinite(n.x()) || n.norm() < 0.5) n = Vec3::UnitZ();
    normals[i] = n.normalized();
  });
  return normals;
}

namespace {

/// Union-find with union by size (ties: the smaller root index wins) and path halving; finds without
/// writes (for parallel readers) are kept short by the union rule.
class Components {
 public:
  explicit Components(std::size_t n) : parent_(n), size_(n, 1) { std::iota(parent_.begin(), parent_.end(), 0); }
  int find(int x) {
    while (parent_[x] != x) x = parent_[x] = parent_[parent_[x]];
    return x;
  }
  int root(int x) const {
    while (parent_[x] != x) x = parent_[x];
    return x;
  }
  bool unite(int a, int b) {
    a = find(a);
    b = find(b);
    if (a == b) return false;
    if (size_[a] < size_[b] || (size_[a] == size_[b] && b < a)) std::swap(a, b);
    parent_[b] = a;
    size_[a] += size_[b];
    return true;
  }

 private:
  std::vector<int> parent_, size_;
};

}  // namespace

// Minimum-spanning-tree orientation, the algorithm of CGAL's mst_orient_normals on the kNN graph: the
// "Riemannian graph" has an edge {i, j} for each j among the first k neighbours of i with j > i, of weight
// float(1 - |n_i . n_j|); the highest point (largest z, the first of equals) is turned to +z and is the root;
// a point reached through the tree is turned to agree with its parent. Edges are ordered by (weight, i,
// position of j in i's row), a strict order, so the minimum spanning forest is unique; it is found by
// Borůvka rounds (each component's lightest outgoing edge, all components at once, in parallel), and
// equals what Prim from the root gives under that order (CGAL's Boost Prim breaks ties of equal float
// weights its own way). Returns, per point, whether the root's tree holds it.
std::vector<char> mst_orient(const std::vector<Vec3>& pts, std::vector<Vec3>& normals, const KnnGraph& g, int k) {
  const std::size_t n = pts.size();
  k = std::min(k, g.k);
  std::vector<char> reached(n, 0);
  if (n == 0) return reached;
  std::size_t top = 0;
  for (std::size_t i = 1; i < n; ++i)
    if (pts[top].z() < pts[i].z()) top = i;
  if (normals[top].z() < 0) normals[top] = -normals[top];

  // Key of edge (i, a): float weight bits (non-negative floats order as their bits), then i * k + a.
  auto key = [&](std::size_t i, int a) -> std::uint64_t {
    const Vec3 &u = normals[i], &v = normals[static_cast<std::size_t>(g.row(i)[a])];
    const double dot = u.x() * v.x() + u.y() * v.y() + u.z() * v.z();
    const float w = static_cast<float>(std::max(0.0, 1.0 - std::abs(dot)));
    std::uint32_t bits;
    std::memcpy(&bits, &w, sizeof bits);
    return (static_cast<std::uint64_t>(bits) << 32) | (static_cast<std::uint64_t>(i) * k + static_cast<std::uint64_t>(a));
  };
  constexpr std::uint64_t kNone = std::numeric_limits<std::uint64_t>::max();
  Components sets(n);
  std::vector<int> comp(n);
  std::iota(comp.begin(), comp.end(), 0);
  std::vector<std::atomic<std::uint64_t>> best(n);
  std::vector<std::uint64_t> tree;  // edge ids (i * k + a) of the forest
  for (;;) {
    tbb::parallel_for(std::size_t(0), n, [&](std::size_t c) { best[c].store(kNone, std::memory_order_relaxed); });
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 4096), [&](const tbb::blocked_range<std::size_t>& range) {
      auto lower = [&](std::size_t c, std::uint64_t v) {
        std::uint64_t cur = best[c].load(std::memory_order_relaxed);
        while (v < cur && !best[c].compare_exchange_weak(cur, v, std::memory_order_relaxed)) {}
      };
      for (std::size_t i = range.begin(); i != range.end(); ++i)
        for (int a = 0; a < k; ++a) {
          const std::size_t j = static_cast<std::size_t>(g.row(i)[a]);
          if (j <= i || comp[i] == comp[j]) continue;
          const std::uint64_t kv = key(i, a);
          lower(static_cast<std::size_t>(comp[i]), kv);
          lower(static_cast<std::size_t>(comp[j]), kv);
        }
    });
    std::vector<std::uint64_t> chosen;
    for (std::size_t c = 0; c < n; ++c) {
      const std::uint64_t v = best[c].load(std::memory_order_relaxed);
      if (v != kNone) chosen.push_back(v & 0xffffffffULL);
    }
    if (chosen.empty()) break;
    std::sort(chosen.begin(), chosen.end());
    chosen.erase(std::unique(chosen.begin(), chosen.end()), chosen.end());
    for (const std::uint64_t e : chosen) {
      const std::size_t i = static_cast<std::size_t>(e / static_cast<std::uint64_t>(k));
      const int a = static_cast<int>(e % static_cast<std::uint64_t>(k));
      if (sets.unite(static_cast<int>(i), g.row(i)[a])) tree.push_back(e);
    }
    tbb::parallel_for(std::size_t(0), n, [&](std::size_t i) { comp[i] = sets.root(static_cast<int>(i)); });
  }

  // The root's tree, walked breadth-first: each point turned to agree with its parent.
  std::vector<std::size_t> start(n + 1, 0);
  for (const std::uint64_t e : tree) {
    const std::size_t i = static_cast<std::size_t>(e / static_cast<std::uint64_t>(k));
    ++start[i + 1];
    ++start[static_cast<std::size_t>(g.row(i)[e % static_cast<std::uint64_t>(k)]) + 1];
  }
  for (std::size_t i = 0; i < n; ++i) start[i + 1] += start[i];
  std::vector<int> adj(start.back());
  {
    std::vector<std::size_t> fill(start.begin(), start.end() - 1);
    for (const std::uint64_t e : tree) {
      const std::size_t i = static_cast<std::size_t>(e / static_cast<std::uint64_t>(k));
      const std::size_t j = static_cast<std::size_t>(g.row(i)[e % static_cast<std::uint64_t>(k)]);
      adj[fill[i]++] = static_cast<int>(j);
      adj[fill[j]++] = static_cast<int>(i);
    }
  }
  std::vector<int> queue{static_cast<int>(top)};
  reached[top] = 1;
  for (std::size_t head = 0; head < queue.size(); ++head) {
    const std::size_t u = static_cast<std::size_t>(queue[head]);
    for (std::size_t e = start[u]; e < start[u + 1]; ++e) {
      const std::size_t v = static_cast<std::size_t>(adj[e]);
      if (reached[v]) continue;
      reached[v] = 1;
      if (normals[u].dot(normals[v]) < 0) normals[v] = -normals[v];
      queue.push_back(static_cast<int>(v));
    }
  }
  return reached;
}

}  // namespace hsr::structure_detail
