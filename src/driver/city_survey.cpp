// The points a tile of a survey is planned with (city_survey.h).
#include "driver/city_survey.h"

#include "core/log.h"
#include "io/io.h"

namespace hsr::city {

namespace {

/// Appends the values of `from` at `keep` to `into` when both have the field (a field `into` has and `from`
/// lacks is cleared: the merged cloud keeps only fields every part has).
template <class T>
void append_field(std::vector<T>& into, const std::vector<T>& from, const std::vector<std::size_t>& keep, bool& dropped) {
  if (into.empty()) return;
  if (from.empty()) {
    into.clear();
    dropped = true;
    return;
  }
  for (std::size_t i : keep) into.push_back(from[i]);
}

/// Appends the points of `from` at `keep` to `into` (shifted into its local coordinates) with their attributes.
void append_points(PointCloud& into, const PointCloud& from, const std::vector<std::size_t>& keep) {
  const Vec3 shift = from.origin - into.origin;
  for (std::size_t i : keep) into.points.push_back(from.points[i] + shift);
  bool dropped = false;
  if (!into.normals.empty()) {
    if (from.has_normals()) {
      for (std::size_t i : keep) into.normals.push_back(from.normals[i]);
    } else {
      into.normals.clear();
      dropped = true;
    }
  }
  PointAttributes& a = into.attributes;
  const PointAttributes& b = from.attributes;
  append_field(a.classification, b.classification, keep, dropped);
  append_field(a.return_number, b.return_number, keep, dropped);
  append_field(a.number_of_returns, b.number_of_returns, keep, dropped);
  append_field(a.intensity, b.intensity, keep, dropped);
  append_field(a.gps_time, b.gps_time, keep, dropped);
  append_field(a.rgb, b.rgb, keep, dropped);
  if (dropped) log::warn("city: " + from.source + " lacks a per-point field of " + into.source + ": the field is dropped near the edge");
}

bool plan_inside(const Vec3& p, const BBox& b) {
  return p.x() >= b.min.x() && p.x() <= b.max.x() && p.y() >= b.min.y() && p.y() <= b.max.y();
}

/// Whether a point (file coordinates) of neighbour tile t joins the planned tile's cloud: inside the loaded
/// rectangle, outside the tile's own extent (where tiles are published with overlapping buffers, the tile's
/// own points are there already) and owned by t (owning_tile: of two neighbours that overlap, one gives it).
bool from_neighbour(const Vec3& p, int t, const BBox& own_extent, const BBox& loaded, const SurveyRegion& region) {
  return plan_inside(p, loaded) && !plan_inside(p, own_extent) &&
         owning_tile(p.head<2>(), region.extents, region.edge_tolerance) == t;
}

}  // namespace

std::vector<BBox> survey_extents(const std::vector<std::string>& tiles) {
  std::vector<BBox> out;
  out.reserve(tiles.size());
  for (const std::string& t : tiles) out.push_back(read_extent(t));
  return out;
}

PointCloud read_survey_region(const std::vector<std::string>& tiles, const std::vector<BBox>& extents, int self,
                              PointCloud own, double margin, SurveyRegion& region) {
  region = SurveyRegion{};
  region.extents = extents;
  region.self = self;
  region.own_points = own.size();
  BBox loaded = extents.at(static_cast<std::size_t>(self));
  loaded.min -= Vec3(margin, margin, 0);
  loaded.max += Vec3(margin, margin, 0);
  region.loaded = loaded;
  const BBox& own_extent = extents[static_cast<std::size_t>(self)];
  for (int t : tiles_meeting(loaded, extents, self)) {
    const PointCloud other = read_points(tiles[static_cast<std::size_t>(t)]);
    if (!other.crs.empty() && !own.crs.empty() && other.crs != own.crs)
      log::warn("city: " + other.source + " names another CRS than " + own.source + ": its points are taken as in the same one");
    std::vector<std::size_t> keep;
    for (std::size_t i = 0; i < other.size(); ++i)
      if (from_neighbour(other.points[i] + other.origin, t, own_extent, loaded, region)) keep.push_back(i);
    append_points(own, other, keep);
    log::info("city: " + own.source + ": " + std::to_string(keep.size()) + " points of its neighbour " + other.source +
              " within the tile margin");
  }
  return own;
}

}  // namespace hsr::city
