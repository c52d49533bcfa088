#include "partition/kinetic_growth.h"

#include "core/error.h"
#include "partition/growth_arrangement.h"
#include "partition/growth_rules.h"
#include "partition/growth_time.h"

#include <algorithm>
#include <map>
#include <unordered_map>
#include <memory>
#include <queue>

namespace hsr::partition_internal {

namespace {

// An edge of a face: the ids of its two 3D end points in the domain's PointRegistry, smaller first.
using EdgeKey = std::uint64_t;
EdgeKey edge_key(std::uint32_t a, std::uint32_t b) {
  if (b < a) std::swap(a, b);
  return (static_cast<std::uint64_t>(a) << 32) | b;
}

// "P's region reaches edge `edge` of its face `face` at `time`".
struct Event {
  Time time;
  bool free = false;  // the edge meets the interior of the initial polygon
  bool waited = false;  // wait_at_bounds: re-queued once at the adjacent polygons' arrival time
  int polygon = 0, face = 0, edge = 0;
};
struct EventLater {
  bool operator()(const Event& a, const Event& b) const {
    const int c = compare(a.time, b.time);
    if (c != 0) return c > 0;
    if (a.free != b.free) return !a.free;
    if (a.waited != b.waited) return a.waited;
    if (a.polygon != b.polygon) return a.polygon > b.polygon;
    if (a.face != b.face) return a.face > b.face;
    return a.edge > b.edge;
  }
};

// One growing polygon: its arrangement, its time function, its region's coverage of the edges, and what its
// stopping rule remembers.
struct Grower {
  ArrangementLocator arrangement;
  std::shared_ptr<const ArrivalTime> time_function;
  const ArrivalTime& time;
  std::unordered_map<EdgeKey, int> coverage;  // region faces on each edge (2 = both sides)
  StopState stop;
  std::vector<char> face_inside;  // hierarchical: per face, inside the bounds
  const GrowthPolygon* in;        // the polygon itself (plane, frame, initial shape)
  Grower(const GrowthPolygon& p, const std::vector<IntPlane>& planes, int self, PointRegistry& points)
      : arrangement(p.integer, p.frame, p.domain, planes, self, points),
        time_function(p.time ? p.time : std::make_shared<const ArrivalTime>(p.shape, p.time_scale)),
        time(*time_function),
        in(&p) {}
};

class Growth {
 public:
  Growth(const std::vector<GrowthPolygon>& polygons, const GrowthRules& rules) : rules_(rules), out_(polygons.size()) {
    std::vector<IntPlane> planes;
    for (const GrowthPolygon& p : polygons) planes.push_back(p.integer);
    for (std::size_t i = 0; i < polygons.size(); ++i) {
      growers_.push_back(std::make_unique<Grower>(polygons[i], planes, static_cast<int>(i), points_));
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
      std::pop_heap(queue_.begin(), queue_.end(), EventLater());
      const Event ev = std::move(queue_.back());
      queue_.pop_back();
      step(ev);
    }
    std::vector<std::vector<char>> removed(growers_.size());
    for (std::size_t i = 0; i < growers_.size(); ++i) removed[i].assign(growers_[i]->arrangement.num_faces(), 0);
    if (rules_.hierarchical && rules_.trim) trim(removed);
    for (std::size_t i = 0; i < growers_.size(); ++i) {
      const ArrangementLocator& arr = growers_[i]->arrangement;
      for (int f = 0; f < arr.num_faces(); ++f) {
        if (removed[i][f]) continue;
        const auto& vs = arr.face(f).vs;
        std::vector<P2> poly;
        std::vector<D2> poly_d;
        poly.reserve(vs.size());  // (GMP's rationals move without noexcept: a growing vector copies them)
        poly_d.reserve(vs.size());
        for (const V2& q : vs) {
          poly.push_back(q.p);
          poly_d.push_back({q.u, q.v});  // make_v2's images: approx(q.p)
        }
        out_[i].faces.push_back(std::move(poly));
        out_[i].faces_d.push_back(std::move(poly_d));
        std::vector<Vec3> poly3d;
        poly3d.reserve(vs.size());
        for (std::uint32_t id : arr.face_points(f)) poly3d.push_back(to_double(points_.point(id)));
        out_[i].faces3d.push_back(std::move(poly3d));
      }
    }
    return std::move(out_);
  }

 private:
  // trim: a face on the initial polygon or inside the bounds is kept.
  bool kept_by_trim(const Grower& g, int f) const {
    if (g.face_inside[f]) return true;
    std::vector<P2> pts;
    for (const V2& q : g.arrangement.face(f).vs) pts.push_back(q.p);
    return interiors_overlap(pts, g.in->shape);
  }

  // trim: removing face f of P's region leaves the complex valid when each edge it shares with the rest of
  // the region (coverage 2) is covered on both sides by another region (walls need nothing).
  bool removable(const Grower& g, int f) const {
    const Face& face = g.arrangement.face(f);
    for (std::size_t e = 0; e < face.vs.size(); ++e) {
      if (g.arrangement.is_wall(face.edge_line[e])) continue;
      const EdgeKey key = key_of(g, f, static_cast<int>(e));
      if (g.coverage.at(key) < 2) continue;
      bool other = false;
      for (int q : g.arrangement.line(face.edge_line[e]).owners) {
        auto it = growers_[q]->coverage.find(key);
        if (it != growers_[q]->coverage.end() && it->second >= 2) other = true;
      }
      if (!other) return false;
    }
    return true;
  }

  // trim: removes region faces beyond the bounds and off the initial polygon while the complex stays valid,
  // in a fixed order (polygons in order, faces last-added first), until nothing changes.
  void trim(std::vector<std::vector<char>>& removed) {
    std::vector<std::vector<char>> keep(growers_.size());
    for (std::size_t i = 0; i < growers_.size(); ++i)
      for (int f = 0; f < growers_[i]->arrangement.num_faces(); ++f) keep[i].push_back(kept_by_trim(*growers_[i], f));
    for (bool changed = true; changed;) {
      changed = false;
      for (std::size_t i = 0; i < growers_.size(); ++i) {
        Grower& g = *growers_[i];
        for (int f = g.arrangement.num_faces() - 1; f >= 0; --f) {
          if (keep[i][f] || removed[i][f] || !removable(g, f)) continue;
          removed[i][f] = 1;
          const std::size_t m = g.arrangement.face(f).vs.size();
          for (std::size_t e = 0; e < m; ++e) --g.coverage[key_of(g, f, static_cast<int>(e))];
          changed = true;
        }
      }
    }
  }

  // meet_at_point: the point where P's front first touches the event's edge (P's frame).
  P2 touch_point(const Event& ev) const {
    const Grower& g = *growers_[ev.polygon];
    const Face& f = g.arrangement.face(ev.face);
    return g.time.min_on_segment(f.vs[ev.edge].p, f.vs[(ev.edge + 1) % f.vs.size()].p).point;
  }

  // meet_at_point: the present polygons that reached P's touch point no later than P.
  std::vector<int> arrived_first(const Event& ev, const std::vector<int>& present) const {
    const Grower& g = *growers_[ev.polygon];
    const ExactPoint x = lift(g.in->integer, g.in->frame, touch_point(ev));
    std::vector<int> out;
    for (int q : present) {
      const Grower& o = *growers_[q];
      if (compare(Time::of(o.time.time_of_gauge(o.time.gauge(to_2d(o.in->frame, x)))), ev.time) <= 0) out.push_back(q);
    }
    return out;
  }

  // wait_at_bounds: at an edge on a bound line, P waits (once) until the adjacent polygons owning the line
  // could reach the edge (the latest of their arrival times on it); true when the event was re-queued.
  bool wait_for_neighbour(const Event& ev, int line_id) {
    const Grower& g = *growers_[ev.polygon];
    if (std::none_of(g.stop.bounds.begin(), g.stop.bounds.end(), [&](const Bound& b) { return b.line == line_id; }))
      return false;
    const auto& adj = rules_.adjacent[ev.polygon];
    const auto& pts = g.arrangement.face_points(ev.face);
    const ExactPoint& a = points_.point(pts[ev.edge]);
    const ExactPoint& b = points_.point(pts[(ev.edge + 1) % pts.size()]);
    bool have = false;
    Rational latest;
    for (int q : g.arrangement.line(line_id).owners) {
      if (!std::binary_search(adj.begin(), adj.end(), q)) continue;
      const Grower& o = *growers_[q];
      const Rational t =
          o.time.time_of_gauge(o.time.min_gauge_on_segment(to_2d(o.in->frame, a), to_2d(o.in->frame, b)));
      if (!have || t > latest) latest = t;
      have = true;
    }
    if (!have) return false;
    Time when = Time::of(latest);
    if (compare(when, ev.time) < 0) return false;
    Event again = ev;
    again.time = std::move(when);
    again.waited = true;
    push(std::move(again));
    return true;
  }

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
      Event ev;
      ev.time = g.time.arrival_on_segment(f.vs[e].p, f.vs[(e + 1) % m].p, ev.free);
      ev.polygon = i;
      ev.face = face;
      ev.edge = static_cast<int>(e);
      push(std::move(ev));
    }
    if (rules_.hierarchical) g.face_inside.push_back(inside_bounds(g.stop.bounds, g.arrangement.lines(), f));
  }

  // The stopping rule of the partitioner, for P meeting the polygons present on the edge.
  bool stops(int i, const Event& ev, int line_id, const std::vector<int>& present, const std::vector<int>& unpaid) {
    Grower& g = *growers_[i];
    Collision c{present, unpaid};
    if (!rules_.hierarchical) return kinetic_stops(g.stop, c);
    if (!rules_.cross_to_bounds) return true;
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
      if (rules_.meet_at_point && !present.empty()) present = arrived_first(ev, present);
      for (int q : present)
        if (!std::binary_search(g.stop.paid.begin(), g.stop.paid.end(), q)) unpaid.push_back(q);
      if (unpaid.empty() && rules_.hierarchical && rules_.wait_at_bounds && !ev.waited &&
          wait_for_neighbour(ev, line_id))
        return;
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
  PointRegistry points_;  // before growers_: their arrangements refer to it
  std::vector<std::unique_ptr<Grower>> growers_;
  void push(Event ev) {
    queue_.push_back(std::move(ev));
    std::push_heap(queue_.begin(), queue_.end(), EventLater());
  }
  std::vector<Event> queue_;  // a heap: the next event (smallest by EventLater's order) at the front
  std::vector<GrownRegion> out_;
};

}  // namespace

bool point_in_convex(const P2& p, const std::vector<P2>& polygon) {
  return point_in_convex(p, approx(p), polygon, approx(polygon));
}

bool point_in_convex(const P2& p, const D2& dp, const std::vector<P2>& polygon, const std::vector<D2>& d) {
  const std::size_t n = polygon.size();
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t j = (i + 1) % n;
    if (orient_sign(polygon[i], polygon[j], p, d[i], d[j], dp) < 0) return false;
  }
  return n >= 3;
}

std::vector<GrownRegion> grow_regions(const std::vector<GrowthPolygon>& polygons, const GrowthRules& rules) {
  return Growth(polygons, rules).run();
}

}  // namespace hsr::partition_internal
