// The office model of the synth stage (synth.h, synth_indoor_model_names(); issue 41 item 1): rooms behind
// thin partitions with doorways, furniture turned at any angle (tables on legs, chairs on one post, L-shaped
// desks, cabinets, open shelves) and round pillars, scanned from a few stations per room.
//
// The truth is the interior air, built without CSG as the hall's is (indoor_pieces.h): the air itself is a
// union of axis-aligned boxes (each room, each doorway through a partition) whose faces are the walls, the
// partitions' faces, the floor and the ceilings; every piece of furniture is cut out of it by add_piece
// (its footprint a hole in the floor); a round pillar is a prism of SynthOfficeParams::pillar_sides faces
// whose two ends are holes in the floor and in its room's ceiling. Pieces touch neither a wall nor each
// other, so the solid is closed and 2-manifold by construction.
#include "synth/indoor_pieces.h"

#include "core/error.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>

namespace hsr::synth_detail {
namespace {

/// A room of the office: its box on the floor plan (world metres) and its row.
struct OfficeRoom {
  double x0, x1, y0, y1;
  int row;
};

/// A doorway through a partition: its opening (world metres, from the floor to the door height).
struct Doorway {
  double x0, x1, y0, y1;
};

/// A round pillar: centre and radius (metres), floor to ceiling.
struct Pillar {
  double cx, cy, r;
  int room;
};

// The layout's drawn sizes (synth.h documents them).
constexpr double kRoomLengthMin = 5.5, kRoomLengthMax = 8.5;  ///< along the row, metres
constexpr double kRoomDepthMin = 5.0, kRoomDepthMax = 7.0;    ///< across the row, metres
constexpr double kHeightMin = 2.7, kHeightMax = 3.1;          ///< floor to ceiling, metres
/// Least offset between a partition of the second row and one of the first (metres): closer, the two
/// would leave a sliver of wall no real plan has.
constexpr double kPartitionOffsetMin = 1.0;
/// Least distance of a doorway from the end of the partition it pierces (metres).
constexpr double kDoorEndMargin = 0.5;
/// Keep-out radii on the floor (metres): no piece this close to a station or to a doorway's centre.
constexpr double kStationKeepOut = 0.6, kDoorKeepOut = 1.0;
constexpr double kPillarRadiusMin = 0.15, kPillarRadiusMax = 0.30;  ///< metres
constexpr int kPlacementAttempts = 2000;  ///< draws of a piece's position before the room is drawn again
constexpr int kRoomAttempts = 50;  ///< draws of a room's furniture before it is too small

/// The rooms' ends along a row of the given room lengths (partitions t thick between them): room i spans
/// [edges[2i], edges[2i + 1]].
std::vector<double> row_edges(const std::vector<double>& lengths, double t) {
  std::vector<double> edges{0.0};
  double x = 0;
  for (std::size_t i = 0; i < lengths.size(); ++i) {
    edges.push_back(x = cm(x + lengths[i]));
    if (i + 1 < lengths.size()) edges.push_back(x = cm(x + t));
  }
  return edges;
}

/// n room lengths drawn and scaled so that the row (partitions included) is `total` long.
std::vector<double> row_lengths(std::mt19937_64& rng, int n, double total, double t) {
  std::vector<double> w(static_cast<std::size_t>(n));
  double sum = 0;
  for (double& x : w) sum += (x = draw(rng, kRoomLengthMin, kRoomLengthMax));
  double used = 0;
  for (std::size_t i = 0; i < w.size(); ++i)
    used += (w[i] = i + 1 == w.size() ? total - (n - 1) * t - used : cm(w[i] * (total - (n - 1) * t) / sum));
  return w;
}

/// Places pieces by their turned footprints (a yawed desk's bounding box would waste the room): a piece's
/// own-frame footprint rectangle grown by half the clearance must stay `margin` inside the room (room
/// coordinates, [0, length] x [0, width]), meet no placed piece's (separating axes) and no keep-out disc.
class FootprintPlacer {
 public:
  FootprintPlacer(double length, double width, double margin, double clearance)
      : length_(length), width_(width), margin_(margin), clearance_(clearance) {}
  void keep_out(const Vec3& centre, double radius) { discs_.push_back({centre, radius}); }
  bool fits(const Piece& p) const {
    const Rect r = footprint(p);
    for (const Vec3& c : r.corners)
      if (c.x() < margin_ - 0.5 * clearance_ || c.y() < margin_ - 0.5 * clearance_ ||
          c.x() > length_ - margin_ + 0.5 * clearance_ || c.y() > width_ - margin_ + 0.5 * clearance_)
        return false;
    for (const Rect& o : placed_)
      if (overlap(r, o)) return false;
    for (const auto& [c, radius] : discs_)
      if (distance(r, c) < radius) return false;
    return true;
  }
  void place(const Piece& p) { placed_.push_back(footprint(p)); }

 private:
  struct Rect {
    std::array<Vec3, 4> corners;  ///< counter-clockwise, z = 0
  };
  Rect footprint(const Piece& p) const {
    double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
    for (const Part& q : p.parts) x0 = std::min(x0, q.x0), x1 = std::max(x1, q.x1), y0 = std::min(y0, q.y0), y1 = std::max(y1, q.y1);
    const double g = 0.5 * clearance_;
    return {{p.to_world(x0 - g, y0 - g, 0), p.to_world(x1 + g, y0 - g, 0), p.to_world(x1 + g, y1 + g, 0),
             p.to_world(x0 - g, y1 + g, 0)}};
  }
  /// Two convex quadrilaterals overlap unless an edge normal of one separates them.
  static bool overlap(const Rect& a, const Rect& b) {
    for (const Rect* r : {&a, &b})
      for (int i = 0; i < 4; ++i) {
        const Vec3 e = r->corners[(i + 1) % 4] - r->corners[i], n(e.y(), -e.x(), 0);  // outward
        const double lim = n.dot(r->corners[i]);
        const Rect& other = r == &a ? b : a;
        if (std::all_of(other.corners.begin(), other.corners.end(), [&](const Vec3& c) { return n.dot(c) >= lim; }))
          return false;
      }
    return true;
  }
  /// Distance from a point to the rectangle (0 inside).
  static double distance(const Rect& r, const Vec3& c) {
    bool inside = true;
    double best = 1e300;
    for (int i = 0; i < 4; ++i) {
      const Vec3 a = r.corners[i], b = r.corners[(i + 1) % 4], e = b - a;
      const Vec3 q(c.x(), c.y(), 0);
      if (e.x() * (q.y() - a.y()) - e.y() * (q.x() - a.x()) < 0) inside = false;
      const double s = std::clamp((q - a).dot(e) / e.squaredNorm(), 0.0, 1.0);
      best = std::min(best, (a + s * e - q).norm());
    }
    return inside ? 0.0 : best;
  }
  double length_, width_, margin_, clearance_;
  std::vector<Rect> placed_;
  std::vector<std::pair<Vec3, double>> discs_;
};

/// The pieces' shapes, each in its own frame (synth.h gives the sizes).
Piece office_table(std::mt19937_64& rng) {
  Piece p;
  p.kind = "table";
  const double lx = draw_cm(rng, 1.2, 1.8), ly = draw_cm(rng, 0.7, 0.9), h = draw_cm(rng, 0.72, 0.76);
  const double top = 0.04, leg = 0.05, inset = 0.05;
  p.parts.push_back({0, lx, 0, ly, h - top, h});
  for (double x : {inset, lx - inset - leg})
    for (double y : {inset, ly - inset - leg}) p.parts.push_back({x, cm(x + leg), y, cm(y + leg), 0, h - top});
  return p;
}

Piece office_chair(std::mt19937_64& rng) {
  Piece p;
  p.kind = "chair";
  const double w = draw_cm(rng, 0.44, 0.50), d = draw_cm(rng, 0.44, 0.50), seat = draw_cm(rng, 0.42, 0.48);
  const double cx = cm(0.5 * w), cy = cm(0.5 * d);
  const double spoke = 0.30, bar = 0.025, base = 0.04, post = 0.02, pad = 0.06, back = 0.04;
  p.parts.push_back({cx - spoke, cx + spoke, cy - bar, cy + bar, 0, base});  // the cross base
  p.parts.push_back({cx - bar, cx + bar, cy - spoke, cy + spoke, 0, base});
  p.parts.push_back({cx - post, cx + post, cy - post, cy + post, base, seat});  // the post, within the cross
  p.parts.push_back({0, w, 0, d, seat, seat + pad});
  p.parts.push_back({0, w, d - back, d, seat + pad, cm(seat + pad + draw(rng, 0.35, 0.45))});
  return p;
}

Piece office_desk(std::mt19937_64& rng) {
  Piece p;
  p.kind = "desk";
  const double a = draw_cm(rng, 1.4, 1.8), b = draw_cm(rng, 1.2, 1.6), da = draw_cm(rng, 0.6, 0.8),
               db = draw_cm(rng, 0.6, 0.8), h = draw_cm(rng, 0.72, 0.76);
  const double top = 0.03, panel = 0.02, inset = 0.05;
  p.parts.push_back({0, a, 0, da, h - top, h});  // the L's two arms
  p.parts.push_back({0, db, 0, b, h - top, h});
  p.parts.push_back({a - inset - panel, a - inset, inset, da - inset, 0, h - top});  // a panel under each end
  p.parts.push_back({inset, db - inset, b - inset - panel, b - inset, 0, h - top});
  p.parts.push_back({inset, 0.45, inset, 0.50, 0, h - top});  // the drawer pedestal under the corner
  return p;
}

Piece office_cabinet(std::mt19937_64& rng) {
  Piece p;
  p.kind = "cabinet";
  p.parts.push_back({0, draw_cm(rng, 0.4, 1.2), 0, draw_cm(rng, 0.4, 0.6), 0, draw_cm(rng, 0.8, 2.0)});
  return p;
}

Piece office_shelf(std::mt19937_64& rng) {
  Piece p;
  p.kind = "shelf";
  const double lx = draw_cm(rng, 0.8, 1.6), ly = draw_cm(rng, 0.3, 0.4), h = draw_cm(rng, 1.2, 2.2);
  const double t = 0.02, plinth = 0.08, pitch = 0.35;
  p.parts.push_back({0, t, 0, ly, 0, h});  // sides and back
  p.parts.push_back({lx - t, lx, 0, ly, 0, h});
  p.parts.push_back({t, lx - t, ly - t, ly, 0, h});
  p.parts.push_back({t, lx - t, 0, ly - t, 0, plinth});  // plinth, boards, top
  const int boards = std::max(0, static_cast<int>((h - plinth - t) / pitch) - 1);
  for (int i = 1; i <= boards; ++i) {
    const double z = cm(plinth + i * (h - plinth - t) / (boards + 1));
    p.parts.push_back({t, lx - t, 0, ly - t, z, z + t});
  }
  p.parts.push_back({t, lx - t, 0, ly - t, h - t, h});
  return p;
}

/// The pillar's footprint as a square piece, for the placer only (its truth is the prism).
Piece pillar_footprint(double r) {
  Piece p;
  p.kind = "pillar";
  p.parts.push_back({-r, r, -r, r, 0, 1});
  return p;
}

/// The ring of a pillar at height z, counter-clockwise seen from above.
std::vector<std::uint32_t> pillar_ring(const Pillar& p, int sides, double z, Vertices& vertices) {
  std::vector<std::uint32_t> ring;
  for (int i = 0; i < sides; ++i) {
    const double a = 2.0 * M_PI * i / sides;
    ring.push_back(vertices({p.cx + p.r * std::cos(a), p.cy + p.r * std::sin(a), z}));
  }
  return ring;
}

void check_office_params(const SynthOfficeParams& o) {
  auto bad = [](const std::string& what) { throw Error(Status::BadInput, "synth", "office: " + what); };
  if (o.rooms < 1 || o.rooms > 6) bad("rooms must be 1-6 (got " + std::to_string(o.rooms) + ")");
  if (!(o.partition >= 0.02 && o.partition <= 0.5)) bad("partition must be 0.02-0.5 m");
  if (!(o.door_width >= 0.5 && o.door_width <= 2.0)) bad("door width must be 0.5-2 m");
  if (!(o.door_height >= 1.5 && o.door_height <= 2.5)) bad("door height must be 1.5-2.5 m (below the ceiling)");
  for (int n : {o.tables, o.chairs, o.desks, o.cabinets, o.shelves, o.pillars})
    if (n < 0 || n > 40) bad("piece counts must be 0-40 per room");
  if (o.pillar_sides < 3 || o.pillar_sides > 256) bad("pillar sides must be 3-256");
  if (!(o.turned_share >= 0 && o.turned_share <= 1)) bad("turned share must be 0-1");
  if (o.scanners < 1 || o.scanners > 8) bad("scanners must be 1-8 per room");
  if (!(o.scanner_height > 0.3 && o.scanner_height < kHeightMin - 0.2)) bad("scanner height must be 0.3-2.5 m");
  if (!(o.clearance >= 0.01 && o.clearance <= 2) || !(o.wall_margin >= 0.01 && o.wall_margin <= 2))
    bad("clearance and wall margin must be 0.01-2 m");
}

}  // namespace

Model make_office(const SynthParams& params) {
  const SynthOfficeParams& o = params.office;
  check_office_params(o);
  std::mt19937_64 rng(params.seed * 0x9E3779B97F4A7C15ull ^ 0x6f6666696365ull);  // "office"
  const double t = o.partition, H = draw_cm(rng, kHeightMin, kHeightMax);
  // The plan: one row of up to 3 rooms, two rows from 4 on (the second no longer than the first).
  const int rows = o.rooms >= 4 ? 2 : 1;
  const int in_row[2] = {(o.rooms + rows - 1) / rows, o.rooms - (o.rooms + rows - 1) / rows};
  std::vector<double> lengths(static_cast<std::size_t>(in_row[0]));
  for (double& l : lengths) l = draw_cm(rng, kRoomLengthMin, kRoomLengthMax);
  const std::vector<double> first = row_edges(lengths, t);
  const double length = first.back();
  std::vector<double> second;
  if (rows == 2) {  // the second row: as long, its rooms as long as the first's, its partitions apart from them
    auto plan_ok = [&](const std::vector<double>& e) {
      for (std::size_t i = 0; i + 1 < e.size(); i += 2)
        if (e[i + 1] - e[i] < kRoomLengthMin) return false;
      for (std::size_t i = 1; i + 1 < e.size(); i += 2)
        for (std::size_t j = 1; j + 1 < first.size(); j += 2)
          if (std::abs(e[i] - first[j]) < kPartitionOffsetMin) return false;
      return true;
    };
    for (int attempt = 0; attempt < 1000 && (second.empty() || !plan_ok(second)); ++attempt)
      second = row_edges(row_lengths(rng, in_row[1], length, t), t);
    if (!plan_ok(second) && in_row[1] == in_row[0]) second = first;  // the partitions in line: a cross
    if (second != first && !plan_ok(second))
      throw Error(Status::BadInput, "synth", "office: no plan found for the second row");
  }
  const double depth[2] = {draw_cm(rng, kRoomDepthMin, kRoomDepthMax), draw_cm(rng, kRoomDepthMin, kRoomDepthMax)};
  std::vector<OfficeRoom> rooms;
  for (int r = 0; r < rows; ++r) {
    const std::vector<double>& e = r == 0 ? first : second;
    const double y0 = r == 0 ? 0.0 : cm(depth[0] + t);
    for (std::size_t i = 0; i + 1 < e.size(); i += 2) rooms.push_back({e[i], e[i + 1], y0, cm(y0 + depth[r]), r});
  }
  Model m;
  m.indoor = true;
  m.density = 80.0;
  m.noise_length = 10.0;
  // Doorways: to the next room of the row, and from each room of the second row to the first.
  std::vector<Doorway> doors;
  std::vector<SynthBlock> walls;
  for (std::size_t i = 0; i + 1 < rooms.size(); ++i) {
    const OfficeRoom &a = rooms[i], &b = rooms[i + 1];
    if (a.row != b.row) continue;
    const double yc = cm(draw(rng, a.y0 + kDoorEndMargin + 0.5 * o.door_width, a.y1 - kDoorEndMargin - 0.5 * o.door_width));
    doors.push_back({a.x1, b.x0, cm(yc - 0.5 * o.door_width), cm(yc + 0.5 * o.door_width)});
    walls.push_back({"partition", BBox{Vec3(a.x1, a.y0, 0), Vec3(b.x0, a.y1, H)}, 0.0, BBox{}, Vec3::Zero()});
  }
  if (rows == 2) {
    walls.push_back({"partition", BBox{Vec3(0, depth[0], 0), Vec3(length, cm(depth[0] + t), H)}, 0.0, BBox{}, Vec3::Zero()});
    for (const OfficeRoom& b : rooms) {
      if (b.row != 1) continue;
      const double lo = b.x0 + kDoorEndMargin + 0.5 * o.door_width, hi = b.x1 - kDoorEndMargin - 0.5 * o.door_width;
      bool placed = false;
      for (int attempt = 0; attempt < 1000 && !placed; ++attempt) {
        const double xc = cm(draw(rng, lo, hi));
        for (const OfficeRoom& a : rooms)
          if (a.row == 0 && xc - 0.5 * o.door_width >= a.x0 + kDoorEndMargin &&
              xc + 0.5 * o.door_width <= a.x1 - kDoorEndMargin) {
            doors.push_back({cm(xc - 0.5 * o.door_width), cm(xc + 0.5 * o.door_width), depth[0], b.y0});
            placed = true;
            break;
          }
      }
      if (!placed) throw Error(Status::BadInput, "synth", "office: no doorway found between the rows");
    }
  }
  // The air: the rooms and the doorways, as one piece whose faces face out of it.
  Piece air;
  air.kind = "air";
  for (const OfficeRoom& r : rooms) air.parts.push_back({r.x0, r.x1, r.y0, r.y1, 0, H});
  for (const Doorway& d : doors) air.parts.push_back({d.x0, d.x1, d.y0, d.y1, 0, o.door_height});

  // Stations and furniture, room by room (each room's own placer, in room coordinates).
  std::vector<Piece> pieces;
  std::vector<Pillar> pillars;
  const std::pair<const char*, int> kinds[] = {{"pillar", o.pillars}, {"desk", o.desks},      {"table", o.tables},
                                               {"shelf", o.shelves},  {"cabinet", o.cabinets}, {"chair", o.chairs}};
  for (std::size_t ri = 0; ri < rooms.size(); ++ri) {
    const OfficeRoom& room = rooms[ri];
    const double len = room.x1 - room.x0, dep = room.y1 - room.y0;
    std::vector<Vec3> keep_out;  // discs (centre, radius in z) in room coordinates
    for (int s = 0; s < o.scanners; ++s) {
      const double x = cm((s + 0.5) / o.scanners * len + draw(rng, -0.3, 0.3)), y = cm(dep * draw(rng, 0.35, 0.65));
      m.scanners.emplace_back(room.x0 + x, room.y0 + y, o.scanner_height);
      keep_out.emplace_back(x, y, kStationKeepOut);
    }
    for (const Doorway& d : doors) {
      const Vec3 c(0.5 * (d.x0 + d.x1) - room.x0, 0.5 * (d.y0 + d.y1) - room.y0, kDoorKeepOut);
      if (c.x() > -1 && c.x() < len + 1 && c.y() > -1 && c.y() < dep + 1) keep_out.push_back(c);
    }
    // The room's furniture, drawn again from the first piece when one finds no place (a random packing
    // can wall itself in).
    std::vector<Piece> furnished;
    std::vector<Pillar> round;
    bool done = false;
    for (int round_no = 0; round_no < kRoomAttempts && !done; ++round_no) {
      furnished.clear(), round.clear();
      FootprintPlacer placer(len, dep, o.wall_margin, o.clearance);
      for (const Vec3& c : keep_out) placer.keep_out({c.x(), c.y(), 0}, c.z());
      done = true;
      for (const auto& [kind, count] : kinds)
        for (int k = 0; k < count && done; ++k) {
          const std::string name = kind;
          const double radius = name == "pillar" ? draw_cm(rng, kPillarRadiusMin, kPillarRadiusMax) : 0.0;
          Piece p = name == "pillar" ? pillar_footprint(radius)
                    : name == "desk" ? office_desk(rng)
                    : name == "table" ? office_table(rng)
                    : name == "shelf" ? office_shelf(rng)
                    : name == "cabinet" ? office_cabinet(rng)
                                        : office_chair(rng);
          if (name != "pillar")
            p.angle = draw(rng, 0, 1) < o.turned_share ? draw(rng, 0, 2 * M_PI) : 0.5 * M_PI * static_cast<double>(rng() % 4);
          if (name != "pillar" && std::isfinite(o.angle_deg)) p.angle = o.angle_deg * M_PI / 180.0;
          const BBox own = p.bounds();
          bool placed = false;
          for (int attempt = 0; attempt < kPlacementAttempts && !placed; ++attempt) {
            p.ox = draw_cm(rng, -own.min.x(), len - own.max.x());
            p.oy = draw_cm(rng, -own.min.y(), dep - own.max.y());
            placed = placer.fits(p);
          }
          if (!placed) {
            done = false;
            break;
          }
          placer.place(p);
          p.ox += room.x0, p.oy += room.y0;
          if (name == "pillar") round.push_back({p.ox, p.oy, radius, static_cast<int>(ri)});
          else furnished.push_back(std::move(p));
        }
    }
    if (!done)
      throw Error(Status::BadInput, "synth", "office: no room for the furniture of room " + std::to_string(ri + 1) +
                                                 " (fewer pieces, or a larger clearance?)");
    pieces.insert(pieces.end(), furnished.begin(), furnished.end());
    pillars.insert(pillars.end(), round.begin(), round.end());
  }

  // The truth: the air's regions, each piece cut out of it, the pillars' prisms.
  Vertices vertices;
  std::vector<PlanarRegion> regions;
  EdgeSet<std::uint32_t> unused_floor, unused_ceiling, floor_holes;
  add_piece(air, H, vertices, regions, unused_floor, unused_ceiling, PieceRole::Air);
  const std::size_t air_regions = regions.size();
  std::vector<EdgeSet<std::uint32_t>> ceiling_holes(rooms.size());
  EdgeSet<std::uint32_t> no_ceiling;
  for (const Piece& p : pieces) add_piece(p, H, vertices, regions, floor_holes, no_ceiling);
  HSR_ASSERT(no_ceiling.edges().empty(), "synth: office furniture reaches the ceiling");
  for (const Pillar& p : pillars) {
    const std::vector<std::uint32_t> bottom = pillar_ring(p, o.pillar_sides, 0.0, vertices);
    const std::vector<std::uint32_t> top = pillar_ring(p, o.pillar_sides, H, vertices);
    const auto n = bottom.size();
    for (std::size_t i = 0; i < n; ++i) {  // each side faces the pillar's axis (out of the air)
      const std::size_t j = (i + 1) % n;
      PlanarRegion side;
      side.boundary = {{top[i], top[j]}, {top[j], bottom[j]}, {bottom[j], bottom[i]}, {bottom[i], top[i]}};
      const Vec3 mid = 0.5 * (vertices.list()[bottom[i]] + vertices.list()[bottom[j]]);
      side.normal = Vec3(p.cx - mid.x(), p.cy - mid.y(), 0).normalized();
      regions.push_back(std::move(side));
    }
    floor_holes.add_loop(bottom);  // counter-clockwise from above: a hole in the floor (normal down)
    ceiling_holes[static_cast<std::size_t>(p.room)].add_loop({top.rbegin(), top.rend()});
  }
  // The floor (one region: the doorways join the rooms' floors) and each room's ceiling take their holes.
  int floors = 0;
  for (std::size_t r = 0; r < air_regions; ++r) {
    PlanarRegion& region = regions[r];
    const double z = vertices.list()[region.boundary.front().first].z();
    if (region.normal.z() < -0.5) {
      ++floors;
      region.boundary.insert(region.boundary.end(), floor_holes.edges().begin(), floor_holes.edges().end());
    } else if (region.normal.z() > 0.5 && z == H) {
      const Vec3 at = vertices.list()[region.boundary.front().first];
      for (std::size_t ri = 0; ri < rooms.size(); ++ri)
        if (at.x() >= rooms[ri].x0 && at.x() <= rooms[ri].x1 && at.y() >= rooms[ri].y0 && at.y() <= rooms[ri].y1)
          region.boundary.insert(region.boundary.end(), ceiling_holes[ri].edges().begin(), ceiling_holes[ri].edges().end());
    }
  }
  HSR_ASSERT(floors == 1, "synth: the office's floor is not one region");
  m.mesh = mesh_of_regions(vertices.list(), std::move(regions));
  // The blocks: every piece with its own frame; an axis-aligned one (pillar, partition, doorway) is its box.
  auto aligned = [](const std::string& kind, const BBox& box) { return SynthBlock{kind, box, 0.0, box, Vec3::Zero()}; };
  for (const Pillar& p : pillars)
    m.blocks.push_back(aligned("pillar", BBox{Vec3(p.cx - p.r, p.cy - p.r, 0), Vec3(p.cx + p.r, p.cy + p.r, H)}));
  for (const Piece& p : pieces) {
    BBox own;
    for (const Part& q : p.parts) own.extend({q.x0, q.y0, q.z0}), own.extend({q.x1, q.y1, q.z1});
    m.blocks.push_back({p.kind, p.bounds(), p.angle, own, Vec3(p.ox, p.oy, 0)});
  }
  for (const SynthBlock& w : walls) m.blocks.push_back(aligned(w.kind, w.box));
  for (const Doorway& d : doors)
    m.blocks.push_back(aligned("doorway", BBox{Vec3(d.x0, d.y0, 0), Vec3(d.x1, d.y1, o.door_height)}));
  return m;
}

}  // namespace hsr::synth_detail
