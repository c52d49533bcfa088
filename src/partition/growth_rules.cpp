#include "partition/growth_rules.h"

#include <algorithm>

namespace hsr::partition_internal {

std::vector<Bound> find_bounds(const ArrivalTime& time, const std::vector<Line>& lines,
                               const std::vector<char>& adjacent_line) {
  std::vector<Bound> out;
  const Rational half(1, 2);
  for (std::size_t l = 0; l < lines.size(); ++l) {
    if (!adjacent_line[l]) continue;
    Rational lowest;
    if (!time.min_on_line(lines[l], lowest) || lowest < half) continue;  // through the inner half
    out.push_back({static_cast<int>(l), line_sign(lines[l], time.centre())});
  }
  return out;
}

bool inside_bounds(const std::vector<Bound>& bounds, const std::vector<Line>& lines, const Face& face) {
  if (bounds.empty()) return false;  // no bound: no evidence where the polygon ends
  for (const Bound& b : bounds)
    for (const V2& q : face.vs)
      if (b.side * line_sign(lines[b.line], q) < 0) return false;
  return true;
}

std::vector<P2> clip_to_bounds(std::vector<P2> poly, const std::vector<Bound>& bounds, const std::vector<Line>& lines) {
  for (const Bound& b : bounds) {
    if (poly.size() < 3) return {};
    const Line& l = lines[b.line];
    const std::size_t n = poly.size();
    std::vector<Rational> value(n);
    for (std::size_t i = 0; i < n; ++i) value[i] = b.side * (l.a * poly[i].u + l.b * poly[i].v + l.c);
    std::vector<P2> out;
    for (std::size_t i = 0; i < n; ++i) {
      const std::size_t j = (i + 1) % n;
      const int si = sgn(value[i]), sj = sgn(value[j]);
      if (si >= 0) out.push_back(poly[i]);
      if (si * sj < 0) {
        const Rational t = value[i] / (value[i] - value[j]);
        out.push_back({poly[i].u + t * (poly[j].u - poly[i].u), poly[i].v + t * (poly[j].v - poly[i].v)});
      }
    }
    poly = std::move(out);
  }
  return poly;
}

bool kinetic_stops(StopState& st, const Collision& c) {
  const int count = static_cast<int>(c.unpaid.size());
  if (count >= st.budget) return true;
  st.budget -= count;
  return false;
}

bool hierarchical_stops(const StopState& st, const Collision& c, const std::vector<int>& adjacent, int max_crossings) {
  for (int q : c.present)
    if (std::binary_search(adjacent.begin(), adjacent.end(), q)) return true;  // events C
  if (!c.on_the_way) return true;  // events B beyond the bounds
  return st.paid.size() + c.unpaid.size() > static_cast<std::size_t>(max_crossings);
}

void pay(StopState& st, const std::vector<int>& unpaid) {
  st.paid.insert(st.paid.end(), unpaid.begin(), unpaid.end());
  std::sort(st.paid.begin(), st.paid.end());
}

}  // namespace hsr::partition_internal
