// The indoor models of the synth stage (synth.h, synth_indoor_model_names()): a hall full of furniture and a
// meeting room, scanned from inside. The truth is the interior air: the room box minus the furniture.
//
// Every piece of furniture is a union of axis-aligned boxes in its own frame (turned about z and moved as
// a whole), standing on the floor and clear of the walls and of every other piece. So the solid needs no
// general CSG (hundreds of pieces would take Nef polyhedra minutes): each piece's boundary comes from the
// grid of its own box coordinates (a cell is solid when one of the boxes holds it; a face lies between a
// solid and an empty cell), its footprint cuts a hole into the floor (and a pillar's top one into the
// ceiling), and mesh_of_regions (models.cpp) splits every planar region into convex faces exactly as the
// CSG models' regions are split. Closed and 2-manifold by construction: every boundary edge of a piece's
// region is shared with the neighbouring region of the same piece, of the floor or of the ceiling.
#include "synth/indoor_pieces.h"

#include "core/error.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numeric>
#include <random>
#include <set>

namespace hsr::synth_detail {
namespace {

/// A point of a piece's grid: indices into its x, y and z coordinates.
using GridPoint = std::array<int, 3>;

/// A unit face of a piece's grid: its loop (counter-clockwise about its normal, which points into the solid
/// cell, i.e. out of the air) and the key of its plane (axis, grid index, sign).
struct GridFace {
  std::array<int, 3> plane;
  std::vector<GridPoint> loop;
};

/// The boundary of a piece in its grid: the regions of its faces in the room (each with the key of its
/// plane) and the loops of the holes it cuts into the floor and the ceiling.
struct PieceBoundary {
  std::vector<std::pair<std::array<int, 3>, EdgeSet<GridPoint>>> regions;
  EdgeSet<GridPoint> floor, ceiling;
};

/// The piece's boundary in its grid. Furniture: faces on the floor (z = 0) and the ceiling (z = height) are
/// the holes it cuts there; the air: every face is one of its regions.
PieceBoundary piece_boundary(const Piece& piece, const std::array<std::vector<double>, 3>& grid, double height,
                             PieceRole role) {
  const bool furniture = role == PieceRole::Furniture;
  const int n[3] = {static_cast<int>(grid[0].size()) - 1, static_cast<int>(grid[1].size()) - 1,
                    static_cast<int>(grid[2].size()) - 1};
  auto solid = [&](const GridPoint& cell) {
    for (int a = 0; a < 3; ++a)
      if (cell[a] < 0 || cell[a] >= n[a]) return false;
    const double x = 0.5 * (grid[0][cell[0]] + grid[0][cell[0] + 1]), y = 0.5 * (grid[1][cell[1]] + grid[1][cell[1] + 1]),
                 z = 0.5 * (grid[2][cell[2]] + grid[2][cell[2] + 1]);
    for (const Part& p : piece.parts)
      if (x > p.x0 && x < p.x1 && y > p.y0 && y < p.y1 && z > p.z0 && z < p.z1) return true;
    return false;
  };
  PieceBoundary out;
  // Unit faces: across each grid plane of axis a, between a solid and an empty cell.
  std::vector<GridFace> faces;
  for (int a = 0; a < 3; ++a) {
    const int b = (a + 1) % 3, c = (a + 2) % 3;  // b x c = a
    for (int k = 0; k <= n[a]; ++k)
      for (int i = 0; i < n[b]; ++i)
        for (int j = 0; j < n[c]; ++j) {
          GridPoint lo{}, hi{};
          lo[a] = k - 1, hi[a] = k, lo[b] = hi[b] = i, lo[c] = hi[c] = j;
          const bool below = solid(lo), above = solid(hi);
          if (below == above) continue;
          const int sign = above ? 1 : -1;  // towards the solid cell
          std::vector<GridPoint> loop;
          for (const auto& [db, dc] : {std::pair{0, 0}, {1, 0}, {1, 1}, {0, 1}}) {
            GridPoint g{};
            g[a] = k, g[b] = i + db, g[c] = j + dc;
            loop.push_back(g);
          }
          if (sign < 0) std::reverse(loop.begin(), loop.end());
          if (furniture && a == 2 && grid[2][k] == 0.0) {
            HSR_ASSERT(sign > 0, "synth: a piece reaches below the floor");
            out.floor.add_loop(loop);
          } else if (furniture && a == 2 && grid[2][k] == height) {
            HSR_ASSERT(sign < 0, "synth: a piece reaches above the ceiling");
            out.ceiling.add_loop(loop);
          } else {
            faces.push_back({{a, k, sign}, std::move(loop)});
          }
        }
  }
  // Regions: unit faces of one plane key connected through shared edges.
  std::vector<std::size_t> parent(faces.size());
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&](std::size_t f) {
    while (parent[f] != f) f = parent[f] = parent[parent[f]];
    return f;
  };
  std::map<std::pair<std::array<int, 3>, std::pair<GridPoint, GridPoint>>, std::size_t> owner;
  for (std::size_t f = 0; f < faces.size(); ++f) {
    const auto& l = faces[f].loop;
    for (std::size_t i = 0; i < l.size(); ++i) owner[{faces[f].plane, {l[i], l[(i + 1) % l.size()]}}] = f;
  }
  for (const auto& [key, f] : owner) {
    const auto it = owner.find({key.first, {key.second.second, key.second.first}});
    if (it != owner.end()) parent[find(f)] = find(it->second);
  }
  std::map<std::size_t, std::size_t> region_of_root;
  for (std::size_t f = 0; f < faces.size(); ++f) {
    const auto [it, added] = region_of_root.emplace(find(f), out.regions.size());
    if (added) out.regions.push_back({faces[f].plane, {}});
    out.regions[it->second].second.add_loop(faces[f].loop);
  }
  return out;
}

/// The grid points where some boundary of the piece turns (a corner of a region, of a hole, or where a
/// boundary passes twice); the others lie inside straight edges of every boundary through them.
std::set<GridPoint> corners(const PieceBoundary& b) {
  std::set<GridPoint> out;
  auto add = [&](const EdgeSet<GridPoint>& edges) {
    std::map<GridPoint, std::vector<GridPoint>> in, to;
    for (const auto& [u, v] : edges.edges()) {
      to[u].push_back(v);
      in[v].push_back(u);
    }
    for (const auto& [v, next] : to) {
      const auto& prev = in.at(v);
      if (next.size() != 1 || prev.size() != 1) {
        out.insert(v);
        continue;
      }
      for (int a = 0; a < 3; ++a)
        if ((v[a] - prev[0][a] > 0) != (next[0][a] - v[a] > 0) || (v[a] - prev[0][a] < 0) != (next[0][a] - v[a] < 0)) {
          out.insert(v);
          break;
        }
    }
  };
  for (const auto& r : b.regions) add(r.second);
  add(b.floor);
  add(b.ceiling);
  return out;
}

}  // namespace

void add_piece(const Piece& piece, double height, Vertices& vertices, std::vector<PlanarRegion>& regions,
               EdgeSet<std::uint32_t>& floor, EdgeSet<std::uint32_t>& ceiling, PieceRole role) {
  std::array<std::vector<double>, 3> grid;
  for (const Part& p : piece.parts) {
    grid[0].insert(grid[0].end(), {p.x0, p.x1});
    grid[1].insert(grid[1].end(), {p.y0, p.y1});
    grid[2].insert(grid[2].end(), {p.z0, p.z1});
  }
  for (auto& g : grid) {
    std::sort(g.begin(), g.end());
    g.erase(std::unique(g.begin(), g.end()), g.end());
  }
  const PieceBoundary b = piece_boundary(piece, grid, height, role);
  // The air's faces face out of it: the unit faces' loops and normals (into the solid cells) turned round.
  const bool air = role == PieceRole::Air;
  const std::set<GridPoint> needed = corners(b);
  auto vertex = [&](const GridPoint& g) { return vertices(piece.to_world(grid[0][g[0]], grid[1][g[1]], grid[2][g[2]])); };
  // Each boundary's edges between needed vertices: walk from each needed vertex to the next one.
  auto simplified = [&](const EdgeSet<GridPoint>& edges, auto&& emit) {
    std::map<GridPoint, GridPoint> next;
    for (const auto& [u, v] : edges.edges())
      if (!needed.count(u)) next.emplace(u, v);  // a straight vertex has exactly one out-edge
    for (const auto& [u, v] : edges.edges()) {
      if (!needed.count(u)) continue;
      GridPoint w = v;
      while (!needed.count(w)) w = next.at(w);
      emit(vertex(u), vertex(w));
    }
  };
  for (const auto& [plane, edges] : b.regions) {
    PlanarRegion r;
    simplified(edges, [&](std::uint32_t u, std::uint32_t v) {
      r.boundary.push_back(air ? std::pair{v, u} : std::pair{u, v});
    });
    Vec3 normal = Vec3::Zero();
    normal[plane[0]] = air ? -plane[2] : plane[2];
    r.normal = piece.to_world_direction(normal);
    regions.push_back(std::move(r));
  }
  simplified(b.floor, [&](std::uint32_t u, std::uint32_t v) { floor.add({u, v}); });
  simplified(b.ceiling, [&](std::uint32_t u, std::uint32_t v) { ceiling.add({u, v}); });
}

namespace {

/// The interior air of a length x width x height room holding the pieces (which stand on the floor and
/// touch neither a wall nor each other), as a truth mesh with convex faces.
PolygonMesh room_minus_pieces(double length, double width, double height, const std::vector<Piece>& pieces) {
  Vertices vertices;
  std::vector<PlanarRegion> regions;
  EdgeSet<std::uint32_t> floor, ceiling;
  for (const Piece& p : pieces) add_piece(p, height, vertices, regions, floor, ceiling);
  // Floor and ceiling: the outer rectangle (normal out of the air: down, up), the footprints as holes.
  auto v = [&](double x, double y, double z) { return vertices({x, y, z}); };
  const double L = length, W = width, H = height;
  floor.add_loop({v(0, 0, 0), v(0, W, 0), v(L, W, 0), v(L, 0, 0)});
  ceiling.add_loop({v(0, 0, H), v(L, 0, H), v(L, W, H), v(0, W, H)});
  auto region = [&](const EdgeSet<std::uint32_t>& e, const Vec3& normal) {
    regions.push_back({{e.edges().begin(), e.edges().end()}, normal});
  };
  region(floor, -Vec3::UnitZ());
  region(ceiling, Vec3::UnitZ());
  auto wall = [&](std::vector<std::uint32_t> loop, const Vec3& normal) {
    EdgeSet<std::uint32_t> e;
    e.add_loop(loop);
    region(e, normal);
  };
  wall({v(0, 0, 0), v(0, 0, H), v(0, W, H), v(0, W, 0)}, -Vec3::UnitX());
  wall({v(L, 0, 0), v(L, W, 0), v(L, W, H), v(L, 0, H)}, Vec3::UnitX());
  wall({v(0, 0, 0), v(L, 0, 0), v(L, 0, H), v(0, 0, H)}, -Vec3::UnitY());
  wall({v(0, W, 0), v(0, W, H), v(L, W, H), v(L, W, 0)}, Vec3::UnitY());
  return mesh_of_regions(vertices.list(), std::move(regions));
}

/// One block of the hall: its kind and size drawn by the seed (synth.h lists the shares and sizes).
Piece draw_hall_block(std::mt19937_64& rng, double height) {
  Piece p;
  const double u = draw(rng, 0, 1);
  double lx = 0, ly = 0, h = 0;
  if (u < 0.35) {
    p.kind = "desk", lx = draw_cm(rng, 1.2, 1.8), ly = draw_cm(rng, 0.6, 0.9), h = draw_cm(rng, 0.70, 0.78);
  } else if (u < 0.55) {
    p.kind = "cabinet", lx = draw_cm(rng, 0.4, 1.2), ly = draw_cm(rng, 0.4, 0.6), h = draw_cm(rng, 0.8, 2.0);
  } else if (u < 0.70) {
    p.kind = "shelf", lx = draw_cm(rng, 0.8, 2.4), ly = draw_cm(rng, 0.3, 0.45), h = draw_cm(rng, 1.2, 2.4);
  } else if (u < 0.90) {
    p.kind = "crate", lx = draw_cm(rng, 0.3, 0.7), ly = draw_cm(rng, 0.3, 0.7), h = draw_cm(rng, 0.3, 0.6);
  } else {
    p.kind = "pillar", lx = ly = draw_cm(rng, 0.3, 0.8), h = height;
  }
  if (rng() % 2) std::swap(lx, ly);  // along x or along y
  p.parts.push_back({0, lx, 0, ly, 0, h});
  if (p.kind != "pillar" && draw(rng, 0, 1) < 0.15) p.angle = draw(rng, 0.05, 0.5 * M_PI - 0.05);
  return p;
}

/// Distinct planes the pieces add (walls, floor and ceiling not counted): vertical planes keyed by their
/// turned normal and offset, horizontal ones by height; an estimate of what group_planes will find.
class PlaneCounter {
 public:
  explicit PlaneCounter(double height) : height_(height) {}
  void add(const Piece& p) {
    for (const Part& q : p.parts) {
      if (q.z1 < height_) heights_.insert(q.z1);
      if (q.z0 > 0) heights_.insert(q.z0);
      // The four sides: outward normal in the piece's frame and a point on the side.
      const std::pair<Vec3, Vec3> sides[] = {{-Vec3::UnitX(), {q.x0, q.y0, 0}}, {Vec3::UnitX(), {q.x1, q.y0, 0}},
                                             {-Vec3::UnitY(), {q.x0, q.y0, 0}}, {Vec3::UnitY(), {q.x0, q.y1, 0}}};
      for (const auto& [n, on] : sides) {
        const Vec3 w = p.to_world_direction(n), x = p.to_world(on.x(), on.y(), 0);
        vertical_.insert({std::round(std::atan2(w.y(), w.x()) * 1e6), std::round(w.dot(x) * 1e6)});
      }
    }
  }
  std::size_t count() const { return vertical_.size() + heights_.size(); }

 private:
  double height_;
  std::set<std::pair<double, double>> vertical_;
  std::set<double> heights_;
};

Model make_hall(const SynthParams& params) {
  std::mt19937_64 rng(params.seed * 0x9E3779B97F4A7C15ull ^ 0x68616c6cull);  // "hall"
  const int blocks = params.planes > 0 ? 0 : (params.blocks > 0 ? params.blocks : 120);
  // About 4.4 planes per block: the hall is sized for the blocks the plane target needs.
  const double expected = params.planes > 0 ? params.planes / 4.4 : blocks;
  const double scale = std::max(1.0, std::sqrt(expected / 250.0));
  const double L = cm(40 * scale), W = cm(30 * scale), H = 3.5;
  Model m;
  m.indoor = true;
  m.density = 60.0;
  m.noise_length = 10.0;
  // Scanner stations at 1.6 m on a grid of about 10 m; no piece within 0.8 m of one.
  const int nx = std::max(1, static_cast<int>(std::lround(L / 10))), ny = std::max(1, static_cast<int>(std::lround(W / 10)));
  Placer placer(L, W, 0.6, 0.4);
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < ny; ++j) {
      m.scanners.emplace_back(cm((i + 0.5) * L / nx), cm((j + 0.5) * W / ny), 1.6);
      placer.keep_out(m.scanners.back(), 0.8);
    }
  std::vector<Piece> pieces;
  PlaneCounter planes(H);
  int failures = 0;
  while (params.planes > 0 ? static_cast<int>(planes.count()) + 6 < params.planes : static_cast<int>(pieces.size()) < blocks) {
    Piece p = draw_hall_block(rng, H);
    const BBox own = p.bounds();
    p.ox = draw_cm(rng, -own.min.x(), L - own.max.x());
    p.oy = draw_cm(rng, -own.min.y(), W - own.max.y());
    if (!placer.fits(p)) {
      if (++failures > 200000)
        throw Error(Status::BadInput, "synth", "hall: no room for block " + std::to_string(pieces.size() + 1) +
                                                   " in the " + std::to_string(L) + " x " + std::to_string(W) + " m hall");
      continue;
    }
    placer.place(p);
    planes.add(p);
    pieces.push_back(std::move(p));
  }
  m.mesh = room_minus_pieces(L, W, H, pieces);
  for (const Piece& p : pieces) m.blocks.push_back({p.kind, p.bounds(), p.angle, BBox{}, Vec3::Zero()});
  return m;
}

/// A chair in its own frame: the seat block (0.46 m high) and the back panel on its rear edge; it faces -y.
Piece draw_chair(std::mt19937_64& rng) {
  Piece p;
  p.kind = "chair";
  const double w = draw_cm(rng, 0.44, 0.52), d = draw_cm(rng, 0.44, 0.50), seat = draw_cm(rng, 0.44, 0.48);
  const double back = 0.08, top = cm(seat + draw(rng, 0.40, 0.50));
  p.parts.push_back({0, w, 0, d, 0, seat});
  p.parts.push_back({0, w, cm(d - back), d, seat, top});
  return p;
}

Model make_meeting_room(const SynthParams& params) {
  std::mt19937_64 rng(params.seed * 0x9E3779B97F4A7C15ull ^ 0x6d656574ull);  // "meet"
  const int chairs = params.blocks > 0 ? params.blocks : 16;
  const int per_side = (chairs + 1) / 2;
  const double pitch = 0.75;  // table length per chair
  const double table_length = cm(std::max(2.4, per_side * pitch)), table_width = 1.2;
  const double L = cm(std::max(10.0, table_length + 4.0)), W = 7.0, H = 2.8;
  Model m;
  m.indoor = true;
  m.density = 400.0;
  m.noise_length = 10.0;
  const double tx = cm(0.5 * (L - table_length)), ty = cm(0.5 * (W - table_width));
  // Scanners beside the table, beyond the chairs, and at one end.
  m.scanners = {{cm(0.5 * L), cm(ty - 1.6), 1.5}, {cm(0.5 * L), cm(ty + table_width + 1.6), 1.5}, {cm(tx - 1.3), cm(0.5 * W), 1.5}};
  std::vector<Piece> pieces;
  Placer placer(L, W, 0.3, 0.1);
  for (const Vec3& s : m.scanners) placer.keep_out(s, 0.5);
  // The table: a top 6 cm thick on two panel legs, 0.3 m in from its ends.
  Piece table;
  table.kind = "table";
  table.ox = tx, table.oy = ty;
  table.parts.push_back({0, table_length, 0, table_width, 0.68, 0.74});
  for (double x : {0.3, table_length - 0.36})
    table.parts.push_back({cm(x), cm(x + 0.06), 0.15, cm(table_width - 0.15), 0, 0.68});
  placer.place(table);
  pieces.push_back(table);
  // Chairs along both long sides, facing the table, pulled out and turned at random; those that do not fit
  // (they would touch a neighbour) are drawn again, then left out.
  for (int c = 0; c < chairs; ++c) {
    const int side = c % 2, slot = c / 2;
    const double along = tx + (slot + 0.5) * table_length / per_side;
    for (int attempt = 0; attempt < 50; ++attempt) {
      Piece chair = draw_chair(rng);
      const double w = chair.parts[0].x1, d = chair.parts[0].y1;
      const double gap = draw_cm(rng, 0.12, 0.45);
      // Its front (-y of its frame) faces the table: turned half a turn on the near side, then a little.
      chair.angle = (side == 0 ? M_PI : 0.0) + draw(rng, -0.21, 0.21);
      // The seat's centre `gap` plus half its depth off the table's edge.
      const double cy = side == 0 ? ty - gap - 0.5 * d : ty + table_width + gap + 0.5 * d;
      const double cx = along + draw(rng, -0.08, 0.08);
      const Vec3 centre = chair.to_world(0.5 * w, 0.5 * d, 0);  // with ox = oy = 0
      chair.ox = cm(cx) - centre.x();
      chair.oy = cm(cy) - centre.y();
      if (!placer.fits(chair)) continue;
      placer.place(chair);
      pieces.push_back(std::move(chair));
      break;
    }
  }
  // Cabinets along the far wall (y = W), 0.3 m off it.
  for (double x = 0.6; x + 0.8 < L - 0.6;) {
    Piece cab;
    cab.kind = "cabinet";
    const double w = draw_cm(rng, 0.6, 1.2), h = draw_cm(rng, 0.8, 1.9);
    cab.parts.push_back({0, w, 0, 0.45, 0, h});
    cab.ox = cm(x), cab.oy = cm(W - 0.75);
    if (placer.fits(cab)) {
      placer.place(cab);
      pieces.push_back(cab);
    }
    x += w + draw_cm(rng, 0.2, 1.5);
  }
  m.mesh = room_minus_pieces(L, W, H, pieces);
  for (const Piece& p : pieces) m.blocks.push_back({p.kind, p.bounds(), p.angle, BBox{}, Vec3::Zero()});
  return m;
}

}  // namespace

std::optional<Model> build_indoor_model(const std::string& name, const SynthParams& params) {
  if (name == "hall") return make_hall(params);
  if (name == "meeting_room") return make_meeting_room(params);
  if (name == "office") return make_office(params);
  return std::nullopt;
}

}  // namespace hsr::synth_detail
