// The pieces of the indoor models (indoor.cpp: hall, meeting room; office.cpp: office): a piece is a union of
// axis-aligned boxes in its own frame, turned about z and moved; its boundary is cut out of the room's air
// by add_piece. Shared by the indoor generators (one implementation each).
#pragma once

#include "synth/synth_internal.h"

#include <array>
#include <cmath>
#include <map>
#include <random>
#include <set>
#include <string>
#include <utility>
#include <vector>

namespace hsr::synth_detail {

/// A box of a piece in the piece's own frame (metres).
struct Part {
  double x0, x1, y0, y1, z0, z1;
};

/// A piece of furniture: its parts (own frame), turned about z by `angle` and moved by (ox, oy).
struct Piece {
  std::string kind;
  std::vector<Part> parts;
  double angle = 0.0, ox = 0.0, oy = 0.0;
  Vec3 to_world(double x, double y, double z) const {
    if (angle == 0.0) return {ox + x, oy + y, z};
    const double c = std::cos(angle), s = std::sin(angle);
    return {ox + c * x - s * y, oy + s * x + c * y, z};
  }
  Vec3 to_world_direction(const Vec3& d) const {
    const double c = std::cos(angle), s = std::sin(angle);
    return {c * d.x() - s * d.y(), s * d.x() + c * d.y(), d.z()};
  }
  /// Axis-aligned bounds in the world.
  BBox bounds() const {
    BBox b;
    for (const Part& p : parts)
      for (double x : {p.x0, p.x1})
        for (double y : {p.y0, p.y1})
          for (double z : {p.z0, p.z1}) b.extend(to_world(x, y, z));
    return b;
  }
};

/// The nearest value on the 1 cm grid.
inline double cm(double x) { return std::round(100.0 * x) / 100.0; }
inline double draw_cm(std::mt19937_64& rng, double lo, double hi) { return cm(draw(rng, lo, hi)); }

/// The vertices of the model, each stored once (keyed by its coordinates).
class Vertices {
 public:
  std::uint32_t operator()(const Vec3& p) {
    const auto [it, added] = index_.emplace(std::array<double, 3>{p.x(), p.y(), p.z()}, static_cast<std::uint32_t>(list_.size()));
    if (added) list_.push_back(p);
    return it->second;
  }
  const std::vector<Vec3>& list() const { return list_; }

 private:
  std::map<std::array<double, 3>, std::uint32_t> index_;
  std::vector<Vec3> list_;
};

/// Directed edges of loops added to one planar region; an edge and its reverse cancel.
template <class Vertex>
class EdgeSet {
 public:
  using Edge = std::pair<Vertex, Vertex>;
  void add_loop(const std::vector<Vertex>& loop) {
    for (std::size_t i = 0; i < loop.size(); ++i) add({loop[i], loop[(i + 1) % loop.size()]});
  }
  void add(const Edge& e) {
    const auto rev = edges_.find({e.second, e.first});
    if (rev != edges_.end()) edges_.erase(rev);
    else edges_.insert(e);
  }
  const std::set<Edge>& edges() const { return edges_; }

 private:
  std::set<Edge> edges_;
};

/// What a piece's boxes are: furniture standing in the room (its faces bound the air, its footprint is a
/// hole in the floor, a piece reaching the ceiling one in the ceiling) or the air itself (the office's
/// rooms and doorways: its faces are the room's walls, floor and ceilings, facing out of the air).
enum class PieceRole { Furniture, Air };

/// Adds the piece's boundary to `regions`, and (furniture) the holes it cuts to `floor` and `ceiling`, with
/// only the vertices some boundary needs (a straight vertex every boundary through it passes would leave
/// collinear corners in the faces). `height` is the ceiling's (furniture only).
void add_piece(const Piece& piece, double height, Vertices& vertices, std::vector<PlanarRegion>& regions,
               EdgeSet<std::uint32_t>& floor, EdgeSet<std::uint32_t>& ceiling, PieceRole role = PieceRole::Furniture);

/// Places pieces without overlap: a piece's world bounds, grown by half the clearance on every side, must
/// meet no placed piece's and no keep-out disc, and stay `margin` inside the walls.
class Placer {
 public:
  Placer(double length, double width, double margin, double clearance)
      : length_(length), width_(width), margin_(margin), clearance_(clearance) {}
  void keep_out(const Vec3& centre, double radius) { discs_.push_back({centre, radius}); }
  bool fits(const Piece& p) const {
    const BBox b = grown(p);
    if (b.min.x() < margin_ - 0.5 * clearance_ || b.min.y() < margin_ - 0.5 * clearance_ ||
        b.max.x() > length_ - margin_ + 0.5 * clearance_ || b.max.y() > width_ - margin_ + 0.5 * clearance_)
      return false;
    for (const BBox& o : placed_)
      if (b.min.x() < o.max.x() && o.min.x() < b.max.x() && b.min.y() < o.max.y() && o.min.y() < b.max.y()) return false;
    for (const auto& [c, r] : discs_) {
      const double dx = std::max({b.min.x() - c.x(), 0.0, c.x() - b.max.x()});
      const double dy = std::max({b.min.y() - c.y(), 0.0, c.y() - b.max.y()});
      if (dx * dx + dy * dy < r * r) return false;
    }
    return true;
  }
  void place(const Piece& p) { placed_.push_back(grown(p)); }

 private:
  BBox grown(const Piece& p) const {
    BBox b = p.bounds();
    b.min -= Vec3::Constant(0.5 * clearance_);
    b.max += Vec3::Constant(0.5 * clearance_);
    return b;
  }
  double length_, width_, margin_, clearance_;
  std::vector<BBox> placed_;
  std::vector<std::pair<Vec3, double>> discs_;
};

/// The office model (office.cpp; synth.h synth_indoor_model_names()).
Model make_office(const SynthParams& params);

}  // namespace hsr::synth_detail
