// The points a tile of a survey is planned with, streamed (city_survey.h).
#include "driver/city_survey.h"

#include "core/error.h"
#include "core/log.h"
#include "io/io.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <functional>

namespace hsr::city {

namespace {

bool plan_inside(const Vec3& p, const BBox& b) {
  return p.x() >= b.min.x() && p.x() <= b.max.x() && p.y() >= b.min.y() && p.y() <= b.max.y();
}

/// Whether a point (file coordinates) of neighbour tile t joins the planned tile's cloud: inside the loaded
/// rectangle, outside the tile's own extent (where tiles are published with overlapping buffers, the tile's
/// own points are there already) and owned by t (owning_tile: of two neighbours that overlap, one gives it).
bool from_neighbour(const Vec3& p, int t, const BBox& own_extent, const BBox& loaded, const std::vector<BBox>& extents,
                    double edge_tolerance) {
  return plan_inside(p, loaded) && !plan_inside(p, own_extent) && owning_tile(p.head<2>(), extents, edge_tolerance) == t;
}

/// Whether `path` is a LAS/LAZ file (its signature), which read_points shifts to the origin of its bounding box.
bool is_las_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  char head[4] = {};
  return in.read(head, 4) && std::memcmp(head, "LASF", 4) == 0;
}

/// Whether local + origin gives every coordinate of `box` back exactly (io.h local_origin's rule: the origin
/// zero, or every value within a factor 2 of it), so that a point's file position is its local one + origin.
bool shift_is_exact(const BBox& box, const Vec3& origin) {
  for (int k = 0; k < 3; ++k) {
    const double o = origin[k];
    if (o == 0) continue;
    if (!(o > 0 ? (box.min[k] >= o / 2 && box.max[k] <= 2 * o) : (box.max[k] <= o / 2 && box.min[k] >= 2 * o))) return false;
  }
  return true;
}

/// A point as the passes see it: its position in the tile's local coordinates (read_points'), its position in
/// file coordinates as the plan computes it (local + origin), its class and its pulse's return count.
struct SeenPoint {
  Vec3 local, global;
  std::uint8_t cls = 0, returns = 0;
  std::uint64_t index = 0;  ///< its index in the file
};

/// Calls `fn` for every point of `path` in file order. LAS/LAZ: streamed; the local position is the file
/// position minus `origin` (read_points' arithmetic). Other formats: read whole, `origin` set to
/// read_points' origin. `wanted` (null: all): the parts (io.h point_parts) to read, the others skipped.
/// Returns the file's CRS.
std::string visit_points(const std::string& path, bool las, Vec3& origin, const std::function<void(const SeenPoint&)>& fn,
                         const std::vector<char>* wanted = nullptr) {
  SeenPoint s;
  if (!las) {
    if (wanted && !wanted->empty() && !(*wanted)[0]) return "";
    const PointCloud cloud = read_points(path);
    origin = cloud.origin;
    const auto& a = cloud.attributes;
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      s.local = cloud.points[i];
      s.global = s.local + cloud.origin;
      s.cls = a.classification.empty() ? 0 : a.classification[i];
      s.returns = a.number_of_returns.empty() ? 1 : a.number_of_returns[i];
      s.index = i;
      fn(s);
    }
    return cloud.crs;
  }
  const auto run = [&](const PointChunk& c) {
    const auto& a = c.attributes;
    for (std::size_t i = 0; i < c.points.size(); ++i) {
      s.local = c.points[i] - origin;
      s.global = s.local + origin;
      s.cls = a.classification.empty() ? 0 : a.classification[i];
      s.returns = a.number_of_returns.empty() ? 1 : a.number_of_returns[i];
      s.index = c.first + i;
      fn(s);
    }
  };
  return wanted ? read_point_parts(path, *wanted, run) : read_point_chunks(path, run);
}

/// The part (of `parts`, in file order) holding the point of file index `index`, looked for from `part` on
/// (points come in file order); the last part holds every index past it (a file read whole is one part).
std::size_t part_of(const std::vector<PointPart>& parts, std::uint64_t index, std::size_t part) {
  while (part + 1 < parts.size() && index >= parts[part + 1].first) ++part;
  return part;
}

/// Integer division rounded down (a cell index into the index of the block of cells holding it).
std::int64_t floor_div(std::int64_t a, std::int64_t b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }

}  // namespace

std::vector<BBox> survey_extents(const std::vector<std::string>& tiles) {
  std::vector<BBox> out;
  out.reserve(tiles.size());
  for (const std::string& t : tiles) out.push_back(read_extent(t));
  return out;
}

// ------------------------------------------------------------------------------------------ KeepMask

KeepMask::KeepMask(const BBox& area, double cell) : cell_(cell) {
  if (!area.valid()) return;
  i0_ = static_cast<std::int64_t>(std::floor(area.min.x() / cell));
  j0_ = static_cast<std::int64_t>(std::floor(area.min.y() / cell));
  nx_ = static_cast<std::int64_t>(std::floor(area.max.x() / cell)) - i0_ + 1;
  ny_ = static_cast<std::int64_t>(std::floor(area.max.y() / cell)) - j0_ + 1;
  marked_.assign(static_cast<std::size_t>(nx_ * ny_), 0);
}

void KeepMask::mark(double x0, double y0, double x1, double y1) {
  const std::int64_t a = std::max<std::int64_t>(0, static_cast<std::int64_t>(std::floor(x0 / cell_)) - i0_);
  const std::int64_t b = std::min<std::int64_t>(nx_ - 1, static_cast<std::int64_t>(std::floor(x1 / cell_)) - i0_);
  const std::int64_t c = std::max<std::int64_t>(0, static_cast<std::int64_t>(std::floor(y0 / cell_)) - j0_);
  const std::int64_t d = std::min<std::int64_t>(ny_ - 1, static_cast<std::int64_t>(std::floor(y1 / cell_)) - j0_);
  for (std::int64_t j = c; j <= d; ++j)
    for (std::int64_t i = a; i <= b; ++i) marked_[static_cast<std::size_t>(i + nx_ * j)] = 1;
}

void KeepMask::mark_near(const Footprint& footprint, double reach) {
  BBox box;
  for (const FootprintPolygon& poly : footprint)
    for (const Vec2& q : poly.outer) box.extend(Vec3(q.x(), q.y(), 0));
  if (!box.valid() || marked_.empty()) return;
  const double near = reach + 0.5 * std::sqrt(2.0) * cell_;
  const std::int64_t a = std::max<std::int64_t>(0, static_cast<std::int64_t>(std::floor((box.min.x() - near) / cell_)) - i0_);
  const std::int64_t b = std::min<std::int64_t>(nx_ - 1, static_cast<std::int64_t>(std::floor((box.max.x() + near) / cell_)) - i0_);
  const std::int64_t c = std::max<std::int64_t>(0, static_cast<std::int64_t>(std::floor((box.min.y() - near) / cell_)) - j0_);
  const std::int64_t d = std::min<std::int64_t>(ny_ - 1, static_cast<std::int64_t>(std::floor((box.max.y() + near) / cell_)) - j0_);
  for (std::int64_t j = c; j <= d; ++j)
    for (std::int64_t i = a; i <= b; ++i) {
      const Vec2 centre((static_cast<double>(i + i0_) + 0.5) * cell_, (static_cast<double>(j + j0_) + 0.5) * cell_);
      if (inside_footprint(centre.x(), centre.y(), footprint) || distance_to_footprint(centre, footprint) <= near)
        marked_[static_cast<std::size_t>(i + nx_ * j)] = 1;
    }
}

void KeepMask::mark_around(const std::unordered_set<std::uint64_t>& cells, double reach) {
  for (std::uint64_t k : cells) {
    const double x = static_cast<double>(static_cast<std::int32_t>(k >> 32)) * cell_;
    const double y = static_cast<double>(static_cast<std::int32_t>(k & 0xFFFFFFFFu)) * cell_;
    mark(x - reach, y - reach, x + cell_ + reach, y + cell_ + reach);
  }
}

bool KeepMask::contains(double x, double y) const {
  const std::int64_t i = static_cast<std::int64_t>(std::floor(x / cell_)) - i0_, j = static_cast<std::int64_t>(std::floor(y / cell_)) - j0_;
  return i >= 0 && j >= 0 && i < nx_ && j < ny_ && marked_[static_cast<std::size_t>(i + nx_ * j)];
}

std::uint64_t KeepMask::part_key(double x, double y) {
  // The mask's own arithmetic (contains), then whole blocks of kPartCells cells: a point's part cell holds its mask cell.
  const auto i = floor_div(static_cast<std::int64_t>(std::floor(x / RegionReader::kCell)), RegionReader::kPartCells);
  const auto j = floor_div(static_cast<std::int64_t>(std::floor(y / RegionReader::kCell)), RegionReader::kPartCells);
  return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(static_cast<std::int32_t>(i))) << 32) |
         static_cast<std::uint32_t>(static_cast<std::int32_t>(j));
}

std::unordered_set<std::uint64_t> KeepMask::marked_part_cells() const {
  std::unordered_set<std::uint64_t> out;
  if (cell_ != RegionReader::kCell) throw Error(Status::Internal, "city", "marked_part_cells: a mask of another cell");
  for (std::int64_t j = 0; j < ny_; ++j)
    for (std::int64_t i = 0; i < nx_; ++i)
      if (marked_[static_cast<std::size_t>(i + nx_ * j)]) {
        const auto a = floor_div(i + i0_, RegionReader::kPartCells), b = floor_div(j + j0_, RegionReader::kPartCells);
        out.insert((static_cast<std::uint64_t>(static_cast<std::uint32_t>(static_cast<std::int32_t>(a))) << 32) |
                   static_cast<std::uint32_t>(static_cast<std::int32_t>(b)));
      }
  return out;
}

std::uint64_t KeepMask::key(double x, double y, double cell) {
  const auto i = static_cast<std::uint32_t>(static_cast<std::int32_t>(std::floor(x / cell)));
  const auto j = static_cast<std::uint32_t>(static_cast<std::int32_t>(std::floor(y / cell)));
  return (static_cast<std::uint64_t>(i) << 32) | j;
}

// ------------------------------------------------------------------------------------------ SurveyIndex

const SurveyIndex::File* SurveyIndex::find(int tile) const {
  const auto it = files_.find(tile);
  return it == files_.end() ? nullptr : &it->second;
}

void SurveyIndex::remember(int tile, File file) { files_[tile] = std::move(file); }

void SurveyIndex::set_survey(const std::vector<BBox>& extents, double margin) {
  extents_ = extents;
  margin_ = std::max(margin_, margin);
}

void SurveyIndex::forget_after(int planned) {
  for (auto it = files_.begin(); it != files_.end();) {
    const int t = it->first;
    bool needed = t > planned;
    for (int u = planned + 1; !needed && u < static_cast<int>(extents_.size()); ++u) {
      BBox loaded = extents_[static_cast<std::size_t>(u)];
      loaded.min -= Vec3(margin_, margin_, 0);
      loaded.max += Vec3(margin_, margin_, 0);
      needed = static_cast<std::size_t>(t) < extents_.size() && !tiles_meeting(loaded, {extents_[static_cast<std::size_t>(t)]}, -1).empty();
    }
    it = needed ? std::next(it) : files_.erase(it);
  }
}

std::size_t SurveyIndex::bytes() const {
  std::size_t n = 0;
  for (const auto& [t, f] : files_)
    for (const auto& c : f.cells) n += sizeof c + c.capacity() * sizeof(std::uint64_t);
  return n;
}

bool part_cell_meets(std::uint64_t key, const BBox& rect) {
  const double side = RegionReader::kCell * RegionReader::kPartCells;
  const double x = static_cast<double>(static_cast<std::int32_t>(key >> 32)) * side;
  const double y = static_cast<double>(static_cast<std::int32_t>(key & 0xFFFFFFFFu)) * side;
  return x <= rect.max.x() && rect.min.x() <= x + side && y <= rect.max.y() && rect.min.y() <= y + side;
}

// ------------------------------------------------------------------------------------------ RegionReader

RegionReader::RegionReader(const std::vector<std::string>& tiles, int self, bool group_cells, SurveyIndex* index)
    : tiles_(tiles), self_(self), group_cells_(group_cells), index_(index) {
  if (self < 0 || static_cast<std::size_t>(self) >= tiles.size()) throw Error(Status::Internal, "city", "plan: no such tile");
  count_tile(self);
}

void RegionReader::count_tile(int t) {
  const std::string& path = tiles_[static_cast<std::size_t>(t)];
  const bool own = t == self_;
  const bool las = is_las_file(path);
  // The file positions of the census are the streamed ones; the plan's are local + origin, the same where the
  // shift is exact (checked below; else read() keeps every point and tests the plan's positions).
  BBox box;
  std::size_t ground = 0, building = 0;
  std::unordered_set<std::uint64_t> cells;
  Source src;
  src.tile = t;
  const BBox own_extent = own ? BBox{} : extents_[static_cast<std::size_t>(self_)];
  const std::size_t points_before = region_points_;
  src.parts = point_parts(path);
  src.census.resize(src.parts.size());
  // A neighbour decoded whole before in this run (SurveyIndex): only its parts with a point in a cell meeting
  // the loaded rectangle, the only points the census takes of it (from_neighbour); its box and CRS as remembered.
  // The tile's own file is decoded whole (every point is counted). A file decoded whole is remembered.
  // LAS/LAZ only: another format is read whole, and its origin is read_points'.
  const SurveyIndex::File* known = index_ && las && !own ? index_->find(t) : nullptr;
  std::vector<char> wanted;
  if (known) {
    wanted.assign(src.parts.size(), 0);
    for (std::size_t i = 0; i < src.parts.size() && i < known->cells.size(); ++i)
      for (std::uint64_t k : known->cells[i])
        if (part_cell_meets(k, loaded_)) {
          wanted[i] = 1;
          break;
        }
  }
  SurveyIndex::File seen;
  const bool remember = index_ && las && !known && !index_->find(t);
  if (remember) seen.cells.resize(src.parts.size());
  census_parts_total_ += src.parts.size();
  census_parts_read_ += known ? static_cast<std::size_t>(std::count(wanted.begin(), wanted.end(), 1)) : src.parts.size();
  std::size_t part = 0;
  std::string crs = visit_points(path, las, src.origin, [&](const SeenPoint& p) {
    ++census_points_decoded_;
    part = part_of(src.parts, p.index, part);
    if (!known) box.extend(p.global);
    if (remember) {
      const std::uint64_t k = KeepMask::part_key(p.global.x(), p.global.y());
      std::vector<std::uint64_t>& c = seen.cells[part];
      if (c.empty() || c.back() != k) c.push_back(k);
    }
    if (!own && !from_neighbour(p.global, t, own_extent, loaded_, extents_, SurveyRegion{}.edge_tolerance)) return;
    PartCensus& pc = src.census[part];
    pc.ground += p.cls == 2;
    pc.building += p.cls == 6;
    pc.other += p.cls != 2 && p.cls != 6;
    if (p.cls == 2 || p.cls == 6) {  // only these are ever kept by a mask
      const std::uint64_t k = KeepMask::part_key(p.global.x(), p.global.y());
      if (pc.cells.empty() || pc.cells.back() != k) pc.cells.push_back(k);
    }
    area_.extend(p.global);
    ++region_points_;
    ground += p.cls == 2;
    if (p.cls == 2 || p.cls == 6) ++class_counts_[KeepMask::key(p.global.x(), p.global.y(), kCountCell)];
    if (p.cls == 6) {
      ++building;
      if (group_cells_) cells.insert(KeepMask::key(p.global.x(), p.global.y(), kCell));
    }
  }, known ? &wanted : nullptr);
  for (PartCensus& pc : src.census) {
    std::sort(pc.cells.begin(), pc.cells.end());
    pc.cells.erase(std::unique(pc.cells.begin(), pc.cells.end()), pc.cells.end());
    pc.cells.shrink_to_fit();
  }
  if (known) {
    box = known->box;
    crs = known->crs;
  } else if (remember) {
    for (std::vector<std::uint64_t>& c : seen.cells) {
      std::sort(c.begin(), c.end());
      c.erase(std::unique(c.begin(), c.end()), c.end());
      c.shrink_to_fit();
    }
    seen.box = box;
    seen.crs = crs;
    index_->remember(t, std::move(seen));
  }
  if (las) {
    src.origin = local_origin(box, true);
    exact_ = exact_ && shift_is_exact(box, src.origin);
  }
  if (own) {
    crs_ = crs;
    own_box_ = box;
    own_building_ = building;
  } else {
    if (!crs.empty() && !crs_.empty() && crs != crs_)
      log::warn("city: " + path + " names another CRS than " + source() + ": its points are taken as in the same one");
    log::info("city: " + source() + ": " + std::to_string(ground + building) + " ground and building points of its neighbour " + path +
              " within the tile margin" +
              (known ? " (" + std::to_string(std::count(wanted.begin(), wanted.end(), 1)) + " of " + std::to_string(src.parts.size()) +
                           " parts decoded)"
                     : ""));
  }
  src.ground = ground;
  src.building = building;
  src.points = region_points_ - points_before;
  ground_ += ground;
  building_ += building;
  building_cells_.merge(cells);
  sources_.push_back(src);
}

void RegionReader::add_neighbours(double margin) {
  if (tiles_.size() < 2) return;
  extents_ = survey_extents(tiles_);
  loaded_ = extents_[static_cast<std::size_t>(self_)];
  loaded_.min -= Vec3(margin, margin, 0);
  loaded_.max += Vec3(margin, margin, 0);
  if (index_) index_->set_survey(extents_, margin);
  for (int t : tiles_meeting(loaded_, extents_, self_)) count_tile(t);
}

void RegionReader::set_block(const TileBlocks& blocks, int block, const BBox& window) {
  blocks_ = blocks;
  block_ = block;
  window_ = block >= 0 ? window : BBox{};
}

BBox RegionReader::area() const {
  if (block_ < 0 || !area_.valid()) return area_;
  BBox a = area_;
  a.min.x() = std::max(a.min.x(), window_.min.x());
  a.min.y() = std::max(a.min.y(), window_.min.y());
  a.max.x() = std::min(a.max.x(), window_.max.x());
  a.max.y() = std::min(a.max.y(), window_.max.y());
  return a.min.x() <= a.max.x() && a.min.y() <= a.max.y() ? a : BBox{};
}

std::size_t RegionReader::class_points_in(const BBox& window) const {
  std::size_t n = 0;
  for (const auto& [key, count] : class_counts_) {
    const double x = static_cast<double>(static_cast<std::int32_t>(key >> 32)) * kCountCell;
    const double y = static_cast<double>(static_cast<std::int32_t>(key & 0xFFFFFFFFu)) * kCountCell;
    if (x <= window.max.x() && window.min.x() <= x + kCountCell && y <= window.max.y() && window.min.y() <= y + kCountCell) n += count;
  }
  return n;
}

bool RegionReader::plans(const Footprint& footprint) const {
  SurveyRegion region;  // the frame read() gives the plan
  if (tiles_.size() > 1) {
    region.extents = extents_;
    region.self = self_;
  }
  region.blocks = blocks_;
  region.block = block_;
  const Vec3 origin = sources_.front().origin;
  BBox tile_box;
  tile_box.min = own_box_.min - origin;
  tile_box.max = own_box_.max - origin;
  return tile_plans_footprint(footprint, origin, tile_box, region);
}

BBox RegionReader::footprint_reach() const {
  if (block_ >= 0) {  // a block: the footprints holding a point of its window (its own lie inside it)
    BBox r = window_;
    const double grow = SurveyRegion{}.edge_tolerance + 1.0;
    r.min -= Vec3(grow, grow, 0);
    r.max += Vec3(grow, grow, 0);
    return r;
  }
  BBox r = area_;
  if (own_box_.valid()) {
    r.extend(own_box_.min);
    r.extend(own_box_.max);
  }
  if (loaded_.valid()) {
    r.extend(loaded_.min);
    r.extend(loaded_.max);
  }
  if (!r.valid()) return r;
  const double grow = SurveyRegion{}.edge_tolerance + 1.0;  // the owner's tolerance, and a unit for rounding
  r.min -= Vec3(grow, grow, 0);
  r.max += Vec3(grow, grow, 0);
  return r;
}

KeepMask first_keep_mask(const RegionReader& reader, const std::vector<FootprintFeature>* footprints, const CityParams& params) {
  const double complete = std::max(params.ring_outer, params.buffer);  // rings up to this read every ground point
  KeepMask keep(reader.area(), RegionReader::kCell);  // a block's: its window only
  if (footprints) {
    for (const FootprintFeature& f : *footprints)
      if (reader.plans(f.footprint)) keep.mark_near(f.footprint, complete + RegionReader::kSlack);
  } else {
    keep.mark_around(reader.building_cells(), complete + 2 * params.component_cell + RegionReader::kSlack);
  }
  return keep;
}

bool RegionReader::classified(ClassSource classes) const {
  return classes != ClassSource::Filter && ground_ > 0 && building_ > 0 && exact_;
}

std::vector<char> RegionReader::wanted_parts(const Source& src, const std::unordered_set<std::uint64_t>& marked) {
  std::vector<char> wanted(src.parts.size(), 0);
  for (std::size_t i = 0; i < src.parts.size(); ++i)
    for (std::uint64_t k : src.census[i].cells)
      if (marked.count(k)) {
        wanted[i] = 1;
        break;
      }
  return wanted;
}

PointCloud RegionReader::read(const KeepMask* keep, SurveyRegion& region, std::vector<std::uint32_t>* own_building) const {
  region = SurveyRegion{};
  if (tiles_.size() > 1) {
    region.extents = extents_;
    region.self = self_;
    region.loaded = loaded_;
  }
  region.blocks = blocks_;
  region.block = block_;
  const bool windowed = block_ >= 0;
  PointsLeftOut& out = region.left_out;
  PointCloud cloud;
  cloud.source = source();
  cloud.crs = crs_;
  const Vec3 origin = sources_.front().origin;
  cloud.origin = origin;
  auto& cls = cloud.attributes.classification;
  auto& returns = cloud.attributes.number_of_returns;
  // Room for every point that may be kept, reserved, not touched: the pages a vector never writes take no
  // memory, and the vector never grows by copying itself (which held its old and new copies at once).
  // A block: the class 2 and 6 points of the count cells its window meets, not the tile's (virtual memory too
  // is bounded by the block).
  const std::size_t most = keep ? (windowed ? std::min(ground_ + building_, class_points_in(window_)) : ground_ + building_) : region_points_;
  cloud.points.reserve(most);
  cls.reserve(most);
  if (!keep) returns.reserve(most);
  if (own_building) {
    own_building->clear();
    own_building->reserve(most);
  }
  const std::unordered_set<std::uint64_t> marked = keep && !every_part_ ? keep->marked_part_cells() : std::unordered_set<std::uint64_t>{};
  for (const Source& src : sources_) {
    const bool own = src.tile == self_;
    // A block does not read a neighbour whose extent misses its window: none of its points would be kept, and
    // the census counted them (the class line counts every point of the region, as the whole tile's plan).
    if (windowed && !own && tiles_meeting(window_, {extents_[static_cast<std::size_t>(src.tile)]}, -1).empty()) {
      out.ground += src.ground;
      out.building += src.building;
      out.other += src.points - src.ground - src.building;
      continue;
    }
    const std::string& path = tiles_[static_cast<std::size_t>(src.tile)];
    const BBox own_extent = own ? BBox{} : extents_[static_cast<std::size_t>(self_)];
    const Vec3 shift = src.origin - origin;  // a neighbour's local positions into the tile's, as DECISIONS #91 did
    std::size_t taken = 0;
    // With a mask, only the parts holding a class 2 or 6 point in a marked cell are read (wanted_parts); the
    // others' points are counted as left out from the census. A skipped part's class 6 points still take
    // their ranks: each read part's first rank is the class 6 points of the parts before it.
    const std::vector<char> wanted = keep && !every_part_ ? wanted_parts(src, marked) : std::vector<char>(src.parts.size(), 1);
    std::vector<std::uint32_t> first_rank(src.parts.size(), 0);
    for (std::size_t i = 0; i + 1 < src.parts.size(); ++i)
      first_rank[i + 1] = first_rank[i] + static_cast<std::uint32_t>(src.census[i].building);
    for (std::size_t i = 0; i < src.parts.size(); ++i) {
      ++parts_total_;
      if (wanted[i]) {
        ++parts_read_;
        continue;
      }
      const PartCensus& pc = src.census[i];
      out.ground += pc.ground;
      out.building += pc.building;
      out.other += pc.other;
      if (own) out.own_building += pc.building;
    }
    std::size_t part = 0;
    std::uint32_t rank = 0;  // the tile's own class 6 points so far
    Vec3 tile_origin = src.origin;
    visit_points(path, is_las_file(path), tile_origin, [&](const SeenPoint& p) {
      if (!own && !from_neighbour(p.global, src.tile, own_extent, region.loaded, region.extents, region.edge_tolerance)) return;
      if (own) {
        const std::size_t at = part_of(src.parts, p.index, part);
        if (at != part) rank = first_rank[at];
        part = at;
      }
      const std::uint32_t ordinal = own && p.cls == 6 ? rank++ : kNotOwnBuilding;
      if (keep && !((p.cls == 2 || p.cls == 6) && keep->contains(p.global.x(), p.global.y()))) {
        out.ground += p.cls == 2;
        out.building += p.cls == 6;
        out.other += p.cls != 2 && p.cls != 6;
        out.own_building += own && p.cls == 6;
        return;
      }
      cloud.points.push_back(own ? p.local : Vec3(p.local + shift));
      cls.push_back(p.cls);
      if (!keep) returns.push_back(p.returns);
      if (own_building) own_building->push_back(ordinal);
      ++taken;
    }, &wanted);
    if (own) region.own_points = taken;
  }
  if (keep) {
    out.ground_class = ground_ > 0;
    out.building_class = building_ > 0;
    out.extent.min = own_box_.min - origin;
    out.extent.max = own_box_.max - origin;
  }
  return cloud;
}

}  // namespace hsr::city
