#include "partition/kinetic_growth.h"

#include "core/error.h"
#include "partition/growth_arrangement.h"
#include "partition/growth_rules.h"
#include "partition/growth_time.h"

#include <algorithm>
#include <map>
#include <memory>
#include <queue>
#include <cstdio>
#include <cstdlib>

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
  bool waited = false;  // corner_wait: re-queued once at the adjacent polygon's arrival time
  int phase = 0;        // phased: 1 for growth beyond the initial polygon and the bounds
  int polygon = 0, face = 0, edge = 0;
};
struct EventLater {
  bool operator()(const Event& a, const Event& b) const {
    if (a.phase != b.phase) return a.phase > b.phase;
    const int c = cmp(a.time, b.time);
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
  ArrivalTime time;
  std::map<EdgeKey, int, EdgeKeyLess> coverage;  // region faces on each edge (2 = both sides)
  StopState stop;
  std::vector<char> face_inside;  // hierarchical: per face, inside the bounds
  std::vector<int> face_via;      // per face: the last crossing (of other regions) on the way to it, or -1
  std::vector<Line> limits;  // restrict_bounds: lines of initial edges that face no bound (keep positive)
  const GrowthPolygon* in = nullptr;
  Grower(const GrowthPolygon& p, const std::vector<ExactPlane>& planes, int self)
      : arrangement(p.plane, p.frame, p.domain, planes, self), time(p.shape, p.time_scale), in(&p) {}
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
      if (rules.hierarchical && rules.restrict_bounds) g.limits = limits_of(polygons[i], g);
      if (std::getenv("HSR_DEBUG_POLYS") && rules.hierarchical) {
        bool kb = true;  // is K (domain section clipped by bounds) smaller than the domain section?
        std::vector<P2> k = clip_to_bounds(polygons[i].domain, g.stop.bounds, g.arrangement.lines());
        std::fprintf(stderr, "grow id %d: adjacent %zu bounds %zu lines %d K/section %.3f shape/section %.4f\n", polygons[i].id,
                     rules.adjacent[i].size(), g.stop.bounds.size(), g.arrangement.num_lines(),
                     k.size() >= 3 ? Rational(twice_area(k) / twice_area(polygons[i].domain)).get_d() : 0.0,
                     Rational(twice_area(polygons[i].shape) / twice_area(polygons[i].domain)).get_d());
        (void)kb;
      }
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
      on_new_face(static_cast<int>(i), f, -1);
    }
  }

  /// The crossings of pass 1 that led P to an edge on one of its bounds that the adjacent polygon reached:
  /// per polygon, the sorted polygons it may cross.
  std::vector<std::vector<int>> useful_crossings() const {
    std::vector<char> useful(crossings_.size(), 0);
    for (std::size_t i = 0; i < growers_.size(); ++i) {
      const Grower& g = *growers_[i];
      const auto& adj = rules_.adjacent[i];
      for (int f = 0; f < g.arrangement.num_faces(); ++f) {
        if (g.face_via[f] < 0) continue;
        const Face& face = g.arrangement.face(f);
        bool meets = false;
        for (std::size_t e = 0; e < face.vs.size() && !meets; ++e) {
          const int l = face.edge_line[e];
          if (std::none_of(g.stop.bounds.begin(), g.stop.bounds.end(), [&](const Bound& b) { return b.line == l; }))
            continue;
          const EdgeKey key = key_of(g, f, static_cast<int>(e));
          if (rules_.useful_mode == 2) meets = true;
          for (int q : g.arrangement.line(l).owners) {
            if (!std::binary_search(adj.begin(), adj.end(), q)) continue;
            auto it = growers_[q]->coverage.find(key);
            if (it != growers_[q]->coverage.end() && it->second >= 1) meets = true;
          }
        }
        if (meets)
          for (int c = g.face_via[f]; c >= 0 && !useful[c]; c = crossings_[c].parent) useful[c] = 1;
      }
    }
    std::vector<std::vector<int>> out(growers_.size());
    for (std::size_t c = 0; c < crossings_.size(); ++c)
      if (useful[c]) out[crossings_[c].polygon].insert(out[crossings_[c].polygon].end(), crossings_[c].crossed.begin(), crossings_[c].crossed.end());
    for (auto& v : out) {
      std::sort(v.begin(), v.end());
      v.erase(std::unique(v.begin(), v.end()), v.end());
    }
    return out;
  }
  std::size_t num_crossings() const { return crossings_.size(); }

  void grow() {
    while (!queue_.empty()) {
      const Event ev = queue_.top();
      queue_.pop();
      step(ev);
    }
  }

  std::vector<GrownRegion> run() {
    if (std::getenv("HSR_DEBUG_FACES")) {
      long init = 0, ink = 0, beyond = 0;
      for (std::size_t i = 0; i < growers_.size(); ++i) {
        const Grower& g = *growers_[i];
        for (int f = 0; f < g.arrangement.num_faces(); ++f) {
          const Face& face = g.arrangement.face(f);
          std::vector<P2> pts;
          for (const V2& q : face.vs) pts.push_back(q.p);
          if (interiors_overlap(pts, g.in->shape)) ++init;
          else if (rules_.hierarchical && g.face_inside[f]) ++ink;
          else ++beyond;
        }
      }
      std::fprintf(stderr, "faces: initial %ld inside-bounds %ld beyond %ld\n", init, ink, beyond);
    }
    std::vector<std::vector<char>> removed(growers_.size());
    for (std::size_t i = 0; i < growers_.size(); ++i) removed[i].assign(growers_[i]->arrangement.num_faces(), 0);
    if (rules_.trim) trim(removed);
    for (std::size_t i = 0; i < growers_.size(); ++i) {
      const ArrangementLocator& arr = growers_[i]->arrangement;
      for (int f = 0; f < arr.num_faces(); ++f) {
        if (removed[i][f]) continue;
        std::vector<P2> poly;
        for (const V2& q : arr.face(f).vs) poly.push_back(q.p);
        out_[i].faces.push_back(std::move(poly));
      }
    }
    return std::move(out_);
  }

 private:
  // Removes region faces that are neither initial nor inside the bounds while every region still ends on
  // another one: a face goes when each edge it shares with the rest of its region is covered on both sides
  // by some other region.
  void trim(std::vector<std::vector<char>>& removed) {
    std::vector<std::vector<char>> keep(growers_.size());
    for (std::size_t i = 0; i < growers_.size(); ++i) {
      const Grower& g = *growers_[i];
      for (int f = 0; f < g.arrangement.num_faces(); ++f) {
        std::vector<P2> pts;
        for (const V2& q : g.arrangement.face(f).vs) pts.push_back(q.p);
        bool k = interiors_overlap(pts, g.in->shape);
        if (!k && rules_.hierarchical && g.face_inside[f] && rules_.trim_keep < 2 &&
            (rules_.trim_keep != 3 || structural(static_cast<int>(i)))) {
          k = true;
          if (rules_.trim_keep == 1)
            for (const Line& l : limits_of(*g.in, g))
              for (const V2& q : g.arrangement.face(f).vs)
                if (line_sign(l, q) < 0) k = false;
        }
        keep[i].push_back(k);
      }
    }
    for (bool changed = true; changed;) {
      changed = false;
      for (std::size_t i = 0; i < growers_.size(); ++i) {
        Grower& g = *growers_[i];
        for (int f = g.arrangement.num_faces() - 1; f >= 0; --f) {
          if (keep[i][f] || removed[i][f]) continue;
          const Face& face = g.arrangement.face(f);
          bool ok = true;
          for (std::size_t e = 0; e < face.vs.size() && ok; ++e) {
            if (g.arrangement.is_wall(face.edge_line[e])) continue;
            const EdgeKey key = key_of(g, f, static_cast<int>(e));
            if (g.coverage[key] < 2) continue;
            bool other = false;
            for (int q : g.arrangement.line(face.edge_line[e]).owners) {
              auto it = growers_[q]->coverage.find(key);
              if (it != growers_[q]->coverage.end() && it->second >= 2) other = true;
            }
            ok = other;
          }
          if (!ok) continue;
          removed[i][f] = 1;
          for (std::size_t e = 0; e < face.vs.size(); ++e) --g.coverage[key_of(g, f, static_cast<int>(e))];
          changed = true;
        }
      }
    }
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

  // Lines of the initial shape's edges that face no bound (angle above 45 degrees to every bound's outward
  // direction), positive inside.
  static std::vector<Line> limits_of(const GrowthPolygon& p, const Grower& g) {
    std::vector<Line> out;
    const std::size_t n = p.shape.size();
    for (std::size_t j = 0; j < n; ++j) {
      const P2& a = p.shape[j];
      const P2& b = p.shape[(j + 1) % n];
      const Rational nu = b.v - a.v, nv = a.u - b.u;  // outward normal
      bool facing = false;
      for (const Bound& bd : g.stop.bounds) {
        const Line& l = g.arrangement.line(bd.line);
        const Rational mu = -bd.side * l.a, mv = -bd.side * l.b;
        const Rational dot = nu * mu + nv * mv;
        if (sgn(dot) > 0 && 2 * dot * dot >= (nu * nu + nv * nv) * (mu * mu + mv * mv)) facing = true;
      }
      if (!facing) out.push_back(line_through(a, b));
    }
    return out;
  }

  EdgeKey key_of(const Grower& g, int face, int edge) const {
    const auto& pts = g.arrangement.face_points(face);
    return edge_key(pts[edge], pts[(edge + 1) % pts.size()]);
  }

  // A face joined P's region: count its edges' coverage and queue an event per edge that leads out.
  void on_new_face(int i, int face, int via) {
    Grower& g = *growers_[i];
    g.face_via.push_back(via);
    const Face& f = g.arrangement.face(face);
    if (rules_.hierarchical) {
      bool inside = inside_bounds(g.stop.bounds, g.arrangement.lines(), f);
      for (const Line& l : g.limits)
        for (const V2& q : f.vs)
          if (line_sign(l, q) < 0) inside = false;
      g.face_inside.push_back(inside);
    }
    int phase = 0;
    if (rules_.phased && rules_.hierarchical && !g.face_inside[face]) {
      std::vector<P2> pts;
      for (const V2& q : f.vs) pts.push_back(q.p);
      if (!interiors_overlap(pts, g.in->shape)) phase = 1;
    }
    const std::size_t m = f.vs.size();
    for (std::size_t e = 0; e < m; ++e) {
      const int count = ++g.coverage[key_of(g, face, static_cast<int>(e))];
      if (g.arrangement.is_wall(f.edge_line[e]) || count >= 2) continue;
      const Rational gauge = g.time.min_on_segment(f.vs[e].p, f.vs[(e + 1) % m].p).gauge;
      Event ev;
      ev.free = gauge < 1;
      ev.time = g.time.time_of_gauge(gauge);
      ev.phase = ev.free ? 0 : 2 * rules_.levels[i] + phase;
      ev.polygon = i;
      ev.face = face;
      ev.edge = static_cast<int>(e);
      queue_.push(std::move(ev));
    }
  }

  // The stopping rule of the partitioner, for P meeting the polygons present on the edge.
  bool stops(int i, const Event& ev, int line_id, const std::vector<int>& present, const std::vector<int>& unpaid) {
    Grower& g = *growers_[i];
    Collision c{present, unpaid};
    if (!rules_.hierarchical) return kinetic_stops(g.stop, c);
    for (int q : present)
      if (rules_.levels[q] < rules_.levels[i]) return true;  // events A: a polygon of an earlier level
    if (!rules_.cross_to_bounds) return true;
    const bool on_the_way = g.face_inside[ev.face] &&
        std::none_of(g.stop.bounds.begin(), g.stop.bounds.end(), [&](const Bound& b) { return b.line == line_id; });
    if (rules_.later_on_the_way &&
        std::all_of(unpaid.begin(), unpaid.end(), [&](int q) { return rules_.levels[q] > rules_.levels[i]; }))
      return !on_the_way;
    if (rules_.allowed) {
      const auto& ok = (*rules_.allowed)[i];
      for (int q : unpaid)
        if (!std::binary_search(ok.begin(), ok.end(), q)) return true;
    }
    if (!structural(i)) return true;
    if (rules_.cross_smaller > 0)
      for (int q : unpaid)
        if (!(growers_[q]->in->area < rules_.cross_smaller * g.in->area)) return true;
    if (rules_.cross_only_extensions) {  // a polygon's own data (its initial shape) always stops P
      const ExactPoint x = lift(g.in->plane, g.in->frame, touch_point(ev));
      for (int q : unpaid)
        if (point_in_convex(to_2d(growers_[q]->in->frame, x), growers_[q]->in->shape)) return true;
    }
    if (rules_.no_cross_ids && std::binary_search(rules_.no_cross_ids->begin(), rules_.no_cross_ids->end(), g.in->id))
      return true;
    if (rules_.second_order_stops) {
      const auto& adj = rules_.adjacent[i];
      for (int q : present)
        for (int m : rules_.adjacent[q])
          if (std::binary_search(adj.begin(), adj.end(), m)) return true;
    }
    if (rules_.max_cross_gauge > 0 && g.time.gauge(touch_point(ev)) > Rational(rules_.max_cross_gauge)) return true;
    c.on_the_way = g.face_inside[ev.face] &&
                   std::none_of(g.stop.bounds.begin(), g.stop.bounds.end(), [&](const Bound& b) { return b.line == line_id; });
    return hierarchical_stops(g.stop, c, rules_.adjacent[i], rules_.max_crossings);
  }

  bool structural(int i) const {
    if (rules_.cross_min_fraction <= 0) return true;
    double largest = 0;
    for (const auto& o : growers_) largest = std::max(largest, o->in->area);
    if (rules_.largest_area > 0) largest = rules_.largest_area;
    return growers_[i]->in->area >= rules_.cross_min_fraction * largest;
  }

  // The point where P's front first touches the event's edge, and the time each of `others` reaches it.
  P2 touch_point(const Event& ev) const {
    const Grower& g = *growers_[ev.polygon];
    const Face& f = g.arrangement.face(ev.face);
    return g.time.min_on_segment(f.vs[ev.edge].p, f.vs[(ev.edge + 1) % f.vs.size()].p).point;
  }
  Rational time_at(int q, const ExactPoint& x) const {
    const Grower& o = *growers_[q];
    return o.time.time_of_gauge(o.time.gauge(to_2d(o.in->frame, x)));
  }

  // meet_at_point: the present polygons that reached P's touch point no later than P.
  std::vector<int> arrived_first(const Event& ev, const std::vector<int>& present) const {
    const Grower& g = *growers_[ev.polygon];
    const ExactPoint x = lift(g.in->plane, g.in->frame, touch_point(ev));
    std::vector<int> out;
    for (int q : present)
      if (time_at(q, x) <= ev.time) out.push_back(q);
    return out;
  }

  // corner_wait: at a bound line that its adjacent polygon does not cover yet, P waits (once) until that
  // polygon could reach the edge; true when the event was re-queued.
  bool wait_for_neighbour(const Event& ev, int line_id) {
    const Grower& g = *growers_[ev.polygon];
    if (!std::any_of(g.stop.bounds.begin(), g.stop.bounds.end(), [&](const Bound& b) { return b.line == line_id; }))
      return false;
    const auto& adj = rules_.adjacent[ev.polygon];
    const auto& pts = g.arrangement.face_points(ev.face);
    const ExactPoint& a = pts[ev.edge];
    const ExactPoint& b = pts[(ev.edge + 1) % pts.size()];
    bool have = false;
    Rational latest;
    for (int q : g.arrangement.line(line_id).owners) {
      if (!std::binary_search(adj.begin(), adj.end(), q)) continue;
      const Grower& o = *growers_[q];
      const Rational t =
          o.time.time_of_gauge(o.time.min_on_segment(to_2d(o.in->frame, a), to_2d(o.in->frame, b)).gauge);
      if (!have || t > latest) latest = t;
      have = true;
    }
    if (!have || latest < ev.time) return false;
    Event again = ev;
    again.time = latest;
    again.waited = true;
    queue_.push(std::move(again));
    return true;
  }

  void step(const Event& ev) {
    Grower& g = *growers_[ev.polygon];
    const EdgeKey key = key_of(g, ev.face, ev.edge);
    if (g.coverage[key] >= 2) return;  // the face beyond is already in the region
    const int line_id = g.arrangement.face(ev.face).edge_line[ev.edge];
    int via = g.face_via[ev.face];
    if (!ev.free) {
      std::vector<int> present, unpaid;
      for (int q : g.arrangement.line(line_id).owners) {
        auto it = growers_[q]->coverage.find(key);
        if (it != growers_[q]->coverage.end() && it->second >= 2) present.push_back(q);
      }
      if (rules_.meet_at_point && !present.empty()) present = arrived_first(ev, present);
      for (int q : present)
        if (!std::binary_search(g.stop.paid.begin(), g.stop.paid.end(), q)) unpaid.push_back(q);
      if (unpaid.empty() && rules_.corner_wait && !ev.waited && wait_for_neighbour(ev, line_id)) return;
      if (!unpaid.empty()) {
        if (stops(ev.polygon, ev, line_id, present, unpaid)) {
          ++out_[ev.polygon].stops;
          return;
        }
        ++out_[ev.polygon].crossings;
        if (std::getenv("HSR_DEBUG_CROSS")) {
          const P2 x = touch_point(ev);
          std::fprintf(stderr, "cross: polygon %d (id %d) crosses", ev.polygon, g.in->id);
          for (int q : unpaid) std::fprintf(stderr, " %d(id %d)", q, growers_[q]->in->id);
          const ExactPoint X = lift(g.in->plane, g.in->frame, x);
          std::fprintf(stderr, " at t=%.4g (%.4g %.4g %.4g) gauge %.3g\n", ev.time.get_d(), X.x.get_d(), X.y.get_d(), X.z.get_d(), g.time.gauge(x).get_d());
        }
        pay(g.stop, unpaid);
        crossings_.push_back({ev.polygon, unpaid, via});
        via = static_cast<int>(crossings_.size()) - 1;
      }
    }
    bool added = false;
    const int beyond = g.arrangement.beyond(ev.face, ev.edge, added);
    if (added) on_new_face(ev.polygon, beyond, via);
  }

  struct Crossing {
    int polygon = -1;
    std::vector<int> crossed;
    int parent = -1;  // the crossing before it on the way, or -1
  };
  std::vector<Crossing> crossings_;

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
  Growth first(polygons, rules);
  first.grow();
  if (!rules.hierarchical || !rules.useful_crossings || first.num_crossings() == 0) return first.run();
  const std::vector<std::vector<int>> allowed = first.useful_crossings();
  GrowthRules second_rules = rules;
  second_rules.allowed = &allowed;
  Growth second(polygons, second_rules);
  second.grow();
  return second.run();
}

}  // namespace hsr::partition_internal
