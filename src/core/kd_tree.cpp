#include "core/kd_tree.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace hsr {

namespace {

constexpr std::size_t kLeafSize = 16;
constexpr std::size_t kParallelBuild = 1 << 15;  ///< ranges at least this large build their halves in parallel
constexpr double kInf = std::numeric_limits<double>::infinity();

/// (qx-px)^2 + (qy-py)^2 + (qz-pz)^2 in this order: the same doubles as CGAL's Euclidean_distance.
inline double squared_distance(const double* q, double x, double y, double z) {
  const double dx = q[0] - x, dy = q[1] - y, dz = q[2] - z;
  double d = dx * dx;
  d += dy * dy;
  d += dz * dz;
  return d;
}

/// A lower bound of squared_distance(q, p) for every p with lo <= p <= hi (and q within [qlo, qhi]): the
/// per-axis gaps are never above the actual differences (rounding is monotone) and are summed the same way.
inline double gap2(const double* qlo, const double* qhi, const float* lo, const float* hi) {
  double g[3];
  for (int d = 0; d < 3; ++d) g[d] = std::max({0.0, static_cast<double>(lo[d]) - qhi[d], qlo[d] - static_cast<double>(hi[d])});
  double s = g[0] * g[0];
  s += g[1] * g[1];
  s += g[2] * g[2];
  return s;
}

float round_down(double v) {
  float f = static_cast<float>(v);
  return static_cast<double>(f) > v ? std::nextafter(f, -std::numeric_limits<float>::infinity()) : f;
}
float round_up(double v) {
  float f = static_cast<float>(v);
  return static_cast<double>(f) < v ? std::nextafter(f, std::numeric_limits<float>::infinity()) : f;
}

/// The k best (squared distance, index) pairs seen so far, sorted.
class KBest {
 public:
  KBest(int k, int* index, double* d2) : k_(k), index_(index), d2_(d2) {}
  double bound() const { return worst_; }
  void offer(double d, int i) {
    if (d > worst_ || (count_ == k_ && d == worst_ && i > index_[k_ - 1])) return;
    int pos = count_ < k_ ? count_++ : k_ - 1;
    while (pos > 0 && (d2_[pos - 1] > d || (d2_[pos - 1] == d && index_[pos - 1] > i))) {
      d2_[pos] = d2_[pos - 1];
      index_[pos] = index_[pos - 1];
      --pos;
    }
    d2_[pos] = d;
    index_[pos] = i;
    if (count_ == k_) worst_ = d2_[k_ - 1];
  }
  int count() const { return count_; }

 private:
  int k_, count_ = 0;
  int* index_;
  double* d2_;
  double worst_ = kInf;
};

}  // namespace

KdTree::KdTree(const std::vector<Vec3>& points) {
  const std::size_t n = points.size();
  slots_.resize(n);
  for (std::size_t i = 0; i < n; ++i) slots_[i] = {points[i].x(), points[i].y(), points[i].z(), static_cast<int>(i)};
  // Halving [a, b) at a + (b - a) / 2 gives sizes floor/ceil(n / 2^t) at depth t: one depth for all leaves.
  while (((n + (std::size_t(1) << depth_) - 1) >> depth_) > kLeafSize) ++depth_;
  boxes_.resize((std::size_t(2) << depth_) - 1);
  leaf_start_.resize((std::size_t(1) << depth_) + 1);
  leaf_start_.back() = static_cast<std::uint32_t>(n);
  auto coord = [](const Slot& s, int d) { return d == 0 ? s.x : (d == 1 ? s.y : s.z); };
  // Median split on the widest side of the tight box; the box is stored rounded outwards to floats.
  auto build = [&](auto&& self, std::size_t node, std::size_t a, std::size_t b, int depth) -> void {
    double lo[3] = {kInf, kInf, kInf}, hi[3] = {-kInf, -kInf, -kInf};
    for (std::size_t s = a; s < b; ++s)
      for (int d = 0; d < 3; ++d) { lo[d] = std::min(lo[d], coord(slots_[s], d)); hi[d] = std::max(hi[d], coord(slots_[s], d)); }
    Box& box = boxes_[node];
    for (int d = 0; d < 3; ++d) {
      box.lo[d] = a < b ? round_down(lo[d]) : 0.0f;
      box.hi[d] = a < b ? round_up(hi[d]) : -1.0f;  // an empty box is never visited (lo > hi: gap > 0)
    }
    if (depth == depth_) {
      leaf_start_[node - first_leaf()] = static_cast<std::uint32_t>(a);
      return;
    }
    int d = 0;
    for (int e = 1; e < 3; ++e)
      if (hi[e] - lo[e] > hi[d] - lo[d]) d = e;
    const std::size_t mid = a + (b - a) / 2;
    std::nth_element(slots_.begin() + static_cast<std::ptrdiff_t>(a), slots_.begin() + static_cast<std::ptrdiff_t>(mid),
                     slots_.begin() + static_cast<std::ptrdiff_t>(b), [&](const Slot& u, const Slot& v) {
                       const double cu = coord(u, d), cv = coord(v, d);
                       return cu < cv || (cu == cv && u.index < v.index);
                     });
    auto left = [&] { self(self, 2 * node + 1, a, mid, depth + 1); };
    auto right = [&] { self(self, 2 * node + 2, mid, b, depth + 1); };
    if (b - a >= kParallelBuild) tbb::parallel_invoke(left, right);
    else { left(); right(); }
  };
  build(build, 0, 0, n, 0);
}

int KdTree::nearest_k(const Vec3& q, int k, int* index, double* d2) const {
  k = static_cast<int>(std::min<std::size_t>(static_cast<std::size_t>(std::max(k, 0)), size()));
  if (k == 0) return 0;
  std::array<double, 64> local;
  std::vector<double> heap_d2;
  double* dist = d2;
  if (!dist) {
    if (k <= static_cast<int>(local.size())) dist = local.data();
    else { heap_d2.resize(static_cast<std::size_t>(k)); dist = heap_d2.data(); }
  }
  KBest best(k, index, dist);
  const double qq[3] = {q.x(), q.y(), q.z()};
  struct Pending { std::size_t node; double gap; };
  std::array<Pending, 128> stack;
  int top = 0;
  stack[top++] = {0, 0.0};
  const std::size_t leaves = first_leaf();
  while (top > 0) {
    const Pending e = stack[--top];
    if (e.gap > best.bound()) continue;
    if (e.node >= leaves) {
      const std::size_t j = e.node - leaves;
      for (std::size_t s = leaf_start_[j]; s < leaf_start_[j + 1]; ++s) {
        const Slot& p = slots_[s];
        best.offer(squared_distance(qq, p.x, p.y, p.z), p.index);
      }
      continue;
    }
    const std::size_t l = 2 * e.node + 1, r = l + 1;
    const double gl = gap2(qq, qq, boxes_[l].lo, boxes_[l].hi), gr = gap2(qq, qq, boxes_[r].lo, boxes_[r].hi);
    // Nearer child on top (visited first): only the order of the walk, not its result.
    const Pending near = gl <= gr ? Pending{l, gl} : Pending{r, gr}, far = gl <= gr ? Pending{r, gr} : Pending{l, gl};
    const double bound = best.bound();
    if (far.gap <= bound) stack[top++] = far;
    if (near.gap <= bound) stack[top++] = near;
  }
  return best.count();
}

int KdTree::nearest(const Vec3& q, double* d2) const {
  int i = -1;
  double d = 0;
  nearest_k(q, 1, &i, &d);
  if (d2) *d2 = d;
  return i;
}

std::vector<int> KdTree::leaf_order() const {
  std::vector<int> order(slots_.size());
  for (std::size_t s = 0; s < order.size(); ++s) order[s] = slots_[s].index;
  return order;
}

std::vector<int> KdTree::neighbour_rows(int k) const {
  const std::size_t n = size();
  const int kk = k + 1;  // the point itself is among its k + 1 nearest (unless k + 1 duplicates come first)
  std::vector<int> rows(n * static_cast<std::size_t>(std::max(k, 0)), -1);
  if (k <= 0 || static_cast<std::size_t>(k) >= n) return rows;
  const std::size_t leaves = first_leaf();
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, std::size_t(1) << depth_, 64), [&](const tbb::blocked_range<std::size_t>& range) {
    std::vector<int> index(kLeafSize * static_cast<std::size_t>(kk));
    std::vector<double> dist(index.size());
    std::vector<KBest> best;
    struct Pending { std::size_t node; double gap; };
    std::vector<Pending> stack;
    for (std::size_t leaf = range.begin(); leaf != range.end(); ++leaf) {
      const std::size_t a = leaf_start_[leaf], m = leaf_start_[leaf + 1] - a;
      if (m == 0) continue;
      const Box& own = boxes_[leaves + leaf];
      const double qlo[3] = {own.lo[0], own.lo[1], own.lo[2]}, qhi[3] = {own.hi[0], own.hi[1], own.hi[2]};
      best.clear();
      for (std::size_t j = 0; j < m; ++j) best.emplace_back(kk, index.data() + j * kk, dist.data() + j * kk);
      double worst = kInf;  // the largest bound among the leaf's queries
      stack.clear();
      stack.push_back({0, 0.0});
      while (!stack.empty()) {
        const Pending e = stack.back();
        stack.pop_back();
        if (e.gap > worst) continue;
        if (e.node >= leaves) {
          const std::size_t j0 = e.node - leaves;
          const Box& box = boxes_[e.node];
          const std::size_t s0 = leaf_start_[j0], count = leaf_start_[j0 + 1] - s0;
          for (std::size_t j = 0; j < m; ++j) {
            const Slot& q = slots_[a + j];
            const double qq[3] = {q.x, q.y, q.z};
            const double bound = best[j].bound();
            if (gap2(qq, qq, box.lo, box.hi) > bound) continue;
            // All distances first (no branch), then only those within the bound are offered.
            double d[kLeafSize];
            bool any = false;
            for (std::size_t t = 0; t < count; ++t) {
              const Slot& p = slots_[s0 + t];
              d[t] = squared_distance(qq, p.x, p.y, p.z);
              any |= d[t] <= bound;
            }
            if (!any) continue;
            for (std::size_t t = 0; t < count; ++t)
              if (d[t] <= best[j].bound()) best[j].offer(d[t], slots_[s0 + t].index);
          }
          worst = 0;
          for (const KBest& kb : best) worst = std::max(worst, kb.bound());
          continue;
        }
        const std::size_t l = 2 * e.node + 1, r = l + 1;
        const double gl = gap2(qlo, qhi, boxes_[l].lo, boxes_[l].hi), gr = gap2(qlo, qhi, boxes_[r].lo, boxes_[r].hi);
        // Nearer child on top (visited first): only the order of the walk, not its result.
        const Pending near = gl <= gr ? Pending{l, gl} : Pending{r, gr}, far = gl <= gr ? Pending{r, gr} : Pending{l, gl};
        if (far.gap <= worst) stack.push_back(far);
        if (near.gap <= worst) stack.push_back(near);
      }
      for (std::size_t j = 0; j < m; ++j) {
        const int self = slots_[a + j].index;
        int* row = rows.data() + static_cast<std::size_t>(self) * k;
        const int* found = index.data() + j * kk;
        int w = 0;
        for (int t = 0; t < best[j].count() && w < k; ++t)
          if (found[t] != self) row[w++] = found[t];
        for (; w < k; ++w) row[w] = row[w - 1];
      }
    }
  });
  return rows;
}

std::vector<std::vector<int>> linked_groups(const std::vector<Vec3>& points, const std::vector<int>& subset,
                                            double link) {
  std::vector<Vec3> xyz;
  xyz.reserve(subset.size());
  for (int p : subset) xyz.push_back(points[static_cast<std::size_t>(p)]);
  std::vector<int> root(subset.size());
  for (std::size_t i = 0; i < root.size(); ++i) root[i] = static_cast<int>(i);
  auto find = [&](int i) {
    while (root[static_cast<std::size_t>(i)] != i)
      i = root[static_cast<std::size_t>(i)] = root[static_cast<std::size_t>(root[static_cast<std::size_t>(i)])];
    return i;
  };
  constexpr int kNeighbours = 16;
  if (xyz.size() > 1) {
    const KdTree tree(xyz);
    const int k = std::min<int>(kNeighbours, static_cast<int>(xyz.size()) - 1);
    const std::vector<int> rows = tree.neighbour_rows(k);
    for (std::size_t i = 0; i < xyz.size(); ++i)
      for (int t = 0; t < k; ++t) {
        const int j = rows[i * static_cast<std::size_t>(k) + static_cast<std::size_t>(t)];
        if (!((xyz[i] - xyz[static_cast<std::size_t>(j)]).norm() < link)) continue;
        const int a = find(static_cast<int>(i)), b = find(j);
        if (a != b) root[static_cast<std::size_t>(std::max(a, b))] = std::min(a, b);  // the smaller index roots
      }
  }
  std::vector<int> group_of(subset.size(), -1);
  std::vector<std::vector<int>> groups;
  for (std::size_t i = 0; i < subset.size(); ++i) {  // in subset order: groups come by their first member
    const std::size_t r = static_cast<std::size_t>(find(static_cast<int>(i)));
    if (group_of[r] < 0) group_of[r] = static_cast<int>(groups.size()), groups.emplace_back();
    groups[static_cast<std::size_t>(group_of[r])].push_back(subset[i]);
  }
  return groups;
}

}  // namespace hsr
