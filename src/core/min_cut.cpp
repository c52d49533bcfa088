#include "core/min_cut.h"

#include "core/error.h"

// Boost.Graph trips -Wmaybe-uninitialized inside its own iterators (false positive, GCC 12).
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include <boost/graph/adjacency_list.hpp>
#include <boost/graph/boykov_kolmogorov_max_flow.hpp>

#include <algorithm>
#include <cmath>
#include <deque>
#include <string>

namespace hsr {
namespace {

void check_problem(const MinCutProblem& p) {
  auto ok = [](double c) { return std::isfinite(c) && c >= 0.0; };
  if (!ok(p.residual_tolerance)) throw Error(Status::Internal, "min-cut", "negative or non-finite residual tolerance");
  if (p.cost0.size() != p.cost1.size()) throw Error(Status::Internal, "min-cut", "cost0 and cost1 differ in size");
  for (std::size_t i = 0; i < p.cost0.size(); ++i)
    if (!ok(p.cost0[i]) || !ok(p.cost1[i]))
      throw Error(Status::Internal, "min-cut", "negative or non-finite unary cost at node " + std::to_string(i));
  const int n = static_cast<int>(p.cost0.size());
  for (const auto& e : p.edges)
    if (e.a < 0 || e.b < 0 || e.a >= n || e.b >= n || !ok(e.cap_ab) || !ok(e.cap_ba))
      throw Error(Status::Internal, "min-cut", "edge with a node out of range or a negative capacity");
}

}  // namespace

std::vector<bool> min_cut_labels(const MinCutProblem& p) {
  check_problem(p);
  using namespace boost;
  using Traits = adjacency_list_traits<vecS, vecS, directedS>;
  using Graph = adjacency_list<
      vecS, vecS, directedS,
      property<vertex_index_t, long,
               property<vertex_color_t, default_color_type,
                        property<vertex_distance_t, long, property<vertex_predecessor_t, Traits::edge_descriptor>>>>,
      property<edge_capacity_t, double,
               property<edge_residual_capacity_t, double, property<edge_reverse_t, Traits::edge_descriptor>>>>;
  const std::size_t n = p.cost0.size();
  std::vector<bool> label(n, false);
  if (n == 0) return label;
  Graph g(n + 2);
  const auto source = vertex(n, g), sink = vertex(n + 1, g);
  auto cap = get(edge_capacity, g);
  auto rev = get(edge_reverse, g);
  auto res = get(edge_residual_capacity, g);
  auto add = [&](std::size_t a, std::size_t b, double c_ab, double c_ba) {
    const auto e = add_edge(a, b, g).first;
    const auto r = add_edge(b, a, g).first;
    cap[e] = c_ab;
    cap[r] = c_ba;
    rev[e] = r;
    rev[r] = e;
  };
  // Source side = label 1. Cutting s->i puts i on the sink side (label 0) and pays cost0; cutting i->t
  // pays cost1. Only the difference matters; the common part is a constant.
  for (std::size_t i = 0; i < n; ++i) {
    const double base = std::min(p.cost0[i], p.cost1[i]);
    if (p.cost0[i] > base) add(n, i, p.cost0[i] - base, 0.0);
    if (p.cost1[i] > base) add(i, n + 1, p.cost1[i] - base, 0.0);
  }
  // Edge a->b is cut when a is on the source side (1) and b on the sink side (0): pays cap_ab.
  for (const auto& e : p.edges)
    if (e.cap_ab > 0 || e.cap_ba > 0)
      add(static_cast<std::size_t>(e.a), static_cast<std::size_t>(e.b), e.cap_ab, e.cap_ba);
  boykov_kolmogorov_max_flow(g, source, sink);
  // The source side: vertices reachable from the source through edges with residual capacity above
  // p.residual_tolerance. Any such closed set is an optimal cut; with tolerance 0 it is BK's own source tree.
  const double eps = p.residual_tolerance;
  std::vector<bool> reach(n + 2, false);
  std::deque<Graph::vertex_descriptor> queue{source};
  reach[source] = true;
  while (!queue.empty()) {
    const auto a = queue.front();
    queue.pop_front();
    for (auto [it, end] = out_edges(a, g); it != end; ++it) {
      const auto b = target(*it, g);
      if (!reach[b] && res[*it] > eps) {
        reach[b] = true;
        queue.push_back(b);
      }
    }
  }
  for (std::size_t i = 0; i < n; ++i) label[i] = reach[i];
  return label;
}

double min_cut_energy(const MinCutProblem& p, const std::vector<bool>& x) {
  double e = 0.0;
  for (std::size_t i = 0; i < p.cost0.size(); ++i) e += x[i] ? p.cost1[i] : p.cost0[i];
  for (const auto& edge : p.edges) {
    if (x[edge.a] && !x[edge.b]) e += edge.cap_ab;
    if (!x[edge.a] && x[edge.b]) e += edge.cap_ba;
  }
  return e;
}

}  // namespace hsr
