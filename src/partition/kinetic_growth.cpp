#include "partition/kinetic_growth.h"

#include "core/error.h"
#include "partition/growth_arrangement.h"
#include "partition/growth_rules.h"
#include "partition/growth_time.h"

#include <algorithm>
#include <map>
#include <memory>
#include <queue>

namespace hsr::partition_internal {

namespace {

using EdgeKey = std::pair<ExactPoint, ExactPoint>;
struct EdgeKeyLess {
  bool operator()(const EdgeKey& a, const EdgeKey& b) const {
    ExactPointLess less;
    if (less(a.first, b.first)) return true;
    if (less(b.first, a.first)) return false;
    return less(a.second, b.second);
  }
};
EdgeKey edge_key(const ExactPoint& a, const ExactPoint& b) {
  if (ExactPointLess()(b, a)) return {b, a};
  return {a, b};
}

// "P's region reaches edge `edge` of its face `face` at `time`".
struct Event {
  Rational time;
  bool free = false;  // the edge meets the interior of the initial polygon
  int polygon = 0, face = 0, edge = 0;
};
struct EventLater {
  bool operator()(const Event& a, const Event& b) const {
    const int c = cmp(a.time, b.time);
    if (c != 0) return c > 0;
    if (a.free != b.free) return !a.free;
    if (a.polygon != b.polygon) return a.polygon > b.polygon;
    if (a.face != b.face) return a.face > b.face;
    return a.edge > b.edge;
  }
};

// One growing polygon: its arrangement, its time function, its region's coverage of the edges, and what its
// stopping rule remembers.
struct Grower {
  ArrangementLocator arrangement;
  ArrivalTime time;
  std::map<EdgeKey, int, EdgeKeyLess> coverage;  // region faces on each edge (2 = both sides)
  StopState stop;
  std::vector<char> face_inside;  // hierarchical: per face, inside the bounds
  Grower(const GrowthPolygon& p, const std::vector<ExactPlane>& planes, int self)
      : arrangement(p.plane, p.frame, p.domain, planes, self), time(p.shape, p.time_scale) {}
};

class Growth {
 public:
  Growth(const std::vector<GrowthPolygon>& polygons, const GrowthRules& rules) : rules_(rules), out_(polygons.size()) {
    std::vector<ExactPlane> planes;
    for (const GrowthPolygon& p : polygons) planes.push_back(p.plane);
    for (std::size_t i = 0; i < polygons.size(); ++i) {
      growers_.push_back(std::make_unique<Grower>(polygons[i], planes, static_cast<int>(i)));
      Grower& g = *growers_.back();
      g.stop.budget = rules.k;
      if (rules.hierarchical) g.stop.bounds = bounds_of(static_cast<int>(i));
    }
    // Initial faces: the face containing a point inside the start polygon; the free events then flood every
    // face the initial polygon overlaps. Perturbation seed + eps (1, eps): a line through the seed keeps the
    // side its gradient points to.
    for (std::size_t i = 0; i < polygons.size(); ++i) {
      ArrangementLocator& arr = growers_[i]->arrangement;
      bool added = false;
      const int f = arr.locate(polygons[i].seed, [&](int l) {
        const Line& line = arr.line(l);
        return sgn(line.a) != 0 ? sgn(line.a) : sgn(line.b);
      }, added);
      on_new_face(static_cast<int>(i), f);
    }
  }

  std::vector<GrownRegion> run() {
    while (!queue_.empty()) {
      const Event ev = queue_.top();
      queue_.pop();
      step(ev);
    }
    for (std::size_t i = 0; i < growers_.size(); ++i) {
      const ArrangementLocator& arr = growers_[i]->arrangement;
      for (int f = 0; f < arr.num_faces(); ++f) {
        std::vector<P2> poly;
        for (const V2& q : arr.face(f).vs) poly.push_back(q.p);
        out_[i].faces.push_back(std::move(poly));
      }
    }
    return std::move(out_);
  }

 private:
  std::vector<Bound> bounds_of(int i) const {
    const ArrangementLocator& arr = growers_[i]->arrangement;
    const auto& adj = rules_.adjacent[i];
    std::vector<char> adjacent_line(arr.lines().size(), 0);  // walls: never
    for (int l = 0; l < arr.num_lines(); ++l) {
      const auto& owners = arr.line(l).owners;
      adjacent_line[l] = std::any_of(owners.begin(), owners.end(),
                                     [&](int q) { return std::binary_search(adj.begin(), adj.end(), q); });
    }
    return find_bounds(growers_[i]->time, arr.lines(), adjacent_line);
  }

  EdgeKey key_of(const Grower& g, int face, int edge) const {
    const auto& pts = g.arrangement.face_points(face);
    return edge_key(pts[edge], pts[(edge + 1) % pts.size()]);
  }

  // A face joined P's region: count its edges' coverage and queue an event per edge that leads out.
  void on_new_face(int i, int face) {
    Grower& g = *growers_[i];
    const Face& f = g.arrangement.face(face);
    const std::size_t m = f.vs.size();
    for (std::size_t e = 0; e < m; ++e) {
      const int count = ++g.coverage[key_of(g, face, static_cast<int>(e))];
      if (g.arrangement.is_wall(f.edge_line[e]) || count >= 2) continue;
      const Rational gauge = g.time.min_on_segment(f.vs[e].p, f.vs[(e + 1) % m].p).gauge;
      Event ev;
      ev.free = gauge < 1;
      ev.time = g.time.time_of_gauge(gauge);
      ev.polygon = i;
      ev.face = face;
      ev.edge = static_cast<int>(e);
      queue_.push(std::move(ev));
    }
    if (rules_.hierarchical) g.face_inside.push_back(inside_bounds(g.stop.bounds, g.arrangement.lines(), f));
  }

  // The stopping rule of the partitioner, for P meeting the polygons present on the edge.
  bool stops(int i, const Event& ev, int line_id, const std::vector<int>& present, const std::vector<int>& unpaid) {
    Grower& g = *growers_[i];
    Collision c{present, unpaid};
    if (!rules_.hierarchical) return kinetic_stops(g.stop, c);
    c.on_the_way = g.face_inside[ev.face] &&
                   std::none_of(g.stop.bounds.begin(), g.stop.bounds.end(), [&](const Bound& b) { return b.line == line_id; });
    return hierarchical_stops(g.stop, c, rules_.adjacent[i], rules_.max_crossings);
  }

  void step(const Event& ev) {
    Grower& g = *growers_[ev.polygon];
    const EdgeKey key = key_of(g, ev.face, ev.edge);
    if (g.coverage[key] >= 2) return;  // the face beyond is already in the region
    const int line_id = g.arrangement.face(ev.face).edge_line[ev.edge];
    if (!ev.free) {
      std::vector<int> present, unpaid;
      for (int q : g.arrangement.line(line_id).owners) {
        auto it = growers_[q]->coverage.find(key);
        if (it != growers_[q]->coverage.end() && it->second >= 2) present.push_back(q);
      }
      for (int q : present)
        if (!std::binary_search(g.stop.paid.begin(), g.stop.paid.end(), q)) unpaid.push_back(q);
      if (!unpaid.empty()) {
        if (stops(ev.polygon, ev, line_id, present, unpaid)) {
          ++out_[ev.polygon].stops;
          return;
        }
        ++out_[ev.polygon].crossings;
        pay(g.stop, unpaid);
      }
    }
    bool added = false;
    const int beyond = g.arrangement.beyond(ev.face, ev.edge, added);
    if (added) on_new_face(ev.polygon, beyond);
  }

  const GrowthRules& rules_;
  std::vector<std::unique_ptr<Grower>> growers_;
  std::priority_queue<Event, std::vector<Event>, EventLater> queue_;
  std::vector<GrownRegion> out_;
};

}  // namespace

bool point_in_convex(const P2& p, const std::vector<P2>& polygon) {
  const std::size_t n = polygon.size();
  for (std::size_t i = 0; i < n; ++i)
    if (orient_sign(polygon[i], polygon[(i + 1) % n], p) < 0) return false;
  return n >= 3;
}

std::vector<GrownRegion> grow_regions(const std::vector<GrowthPolygon>& polygons, const GrowthRules& rules) {
  return Growth(polygons, rules).run();
}

}  // namespace hsr::partition_internal
