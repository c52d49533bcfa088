// Footprints (footprints.h): hsr's own footprint files read here, every other vector file read and written by
// GDAL/OGR in the module libhsr_gdal.so (footprints_gdal.cpp), loaded the first time a footprint needs it.
#include "city/footprints.h"

#include "city/city_internal.h"
#include "city/footprints_gdal.h"
#include "core/error.h"
#include "core/module.h"

#include <filesystem>
#include <fstream>
#include <map>
#include <optional>

namespace hsr {

namespace fs = std::filesystem;

namespace {

[[noreturn]] void bad(Status s, const std::string& what) { throw Error(s, kCityStage, what); }

/// A ring's corners as given, a corner that repeats the one before dropped, and the closing repeat of the first
/// (OGR's and GeoJSON's rings repeat it).
std::vector<Vec2> distinct_corners(const std::vector<Vec2>& ring) {
  std::vector<Vec2> out;
  for (const Vec2& p : ring)
    if (out.empty() || out.back() != p) out.push_back(p);
  while (out.size() > 1 && out.back() == out.front()) out.pop_back();
  return out;
}

/// A polygon of its rings (outer first, each as distinct_corners gives it); false when the outer ring has fewer
/// than 3 corners. Holes with fewer are dropped.
bool polygon_of_rings(std::vector<std::vector<Vec2>> rings, FootprintPolygon& out) {
  if (rings.empty() || rings.front().size() < 3) return false;
  out.outer = std::move(rings.front());
  for (std::size_t h = 1; h < rings.size(); ++h)
    if (rings[h].size() >= 3) out.holes.push_back(std::move(rings[h]));
  return true;
}

/// A feature of its id, fields and polygons' rings as read (OGR's or GeoJSON's: corners as stored, the closing
/// repeat included): each ring as distinct_corners gives it, each polygon as polygon_of_rings.
FootprintFeature feature_of_rings(std::string id, nlohmann::json attributes,
                                  std::vector<std::vector<std::vector<Vec2>>> polygons) {
  FootprintFeature f;
  f.id = std::move(id);
  f.attributes = std::move(attributes);
  for (std::vector<std::vector<Vec2>>& rings : polygons) {
    for (std::vector<Vec2>& ring : rings) ring = distinct_corners(ring);
    FootprintPolygon fp;
    if (polygon_of_rings(std::move(rings), fp)) f.footprint.push_back(std::move(fp));
  }
  return f;
}

/// Adds a feature read from `path` (the `index`-th, from 1) to `out`: one without a polygon is counted as skipped;
/// an id used before is an error.
void add_feature(FootprintFeature f, std::size_t index, const std::string& path, std::map<std::string, std::size_t>& seen,
                 FootprintSet& out) {
  if (f.footprint.empty()) {
    ++out.skipped;
    return;
  }
  if (!seen.emplace(f.id, index).second)
    bad(Status::BadFormat, "footprints: id '" + f.id + "' is used by features " + std::to_string(seen[f.id]) + " and " +
                               std::to_string(index) + " of '" + path + "' (ids must be unique: --id-field)");
  out.features.push_back(std::move(f));
}

/// The member of footprint_geojson's FeatureCollection that marks it as hsr's own: MultiPolygons in the points'
/// coordinates, nothing else to interpret.
constexpr const char* kOwnFootprintMember = "hsr_footprint";
/// A file larger than this is never taken for one of hsr's own footprint files (those hold one building), bytes.
constexpr std::uintmax_t kOwnFootprintMaxBytes = 1 << 20;

/// The footprints of a file footprint_geojson wrote (kOwnFootprintMember present), read without GDAL, or
/// nullopt for any other file. Why: each building of `hsr city` reads its footprint in its own process, and
/// GDAL's GeoJSON driver gives every layer the WGS 84 CRS, whose making opens and parses PROJ's database:
/// about 10 ms of CPU a building (perf on a 1,000-building tile: 7 % of all the city's samples), more than the
/// building's partition. The polygons are GDAL's to the bit (the same doubles, the same ring rules).
std::optional<FootprintSet> read_own_footprints(const std::string& path, const FootprintReadParams& params) {
  const fs::path p(path);
  std::error_code ec;
  if ((p.extension() != ".geojson" && p.extension() != ".json") || fs::file_size(p, ec) > kOwnFootprintMaxBytes || ec)
    return std::nullopt;
  std::ifstream in(path);
  const nlohmann::json doc = nlohmann::json::parse(in, nullptr, false);
  if (!doc.is_object() || !doc.contains(kOwnFootprintMember)) return std::nullopt;
  FootprintSet out;
  out.crs_note = "CRS not checked: hsr's own footprint file, in the points' coordinates";
  std::map<std::string, std::size_t> seen;
  try {
    std::size_t index = 0;
    for (const nlohmann::json& feature : doc.at("features")) {
      ++index;
      nlohmann::json attributes = feature.value("properties", nlohmann::json::object());
      if (!params.id_field.empty() && !attributes.contains(params.id_field))
        bad(Status::BadFormat, "footprints: '" + path + "' has no field '" + params.id_field + "' (--id-field)");
      const nlohmann::json& id = params.id_field.empty() ? feature.at("id") : attributes.at(params.id_field);
      std::vector<std::vector<std::vector<Vec2>>> polygons;
      for (const nlohmann::json& polygon : feature.at("geometry").at("coordinates")) {
        std::vector<std::vector<Vec2>>& rings = polygons.emplace_back();
        for (const nlohmann::json& ring : polygon) {
          std::vector<Vec2>& corners = rings.emplace_back();
          for (const nlohmann::json& xy : ring) corners.emplace_back(xy.at(0).get<double>(), xy.at(1).get<double>());
        }
      }
      add_feature(feature_of_rings(id.is_string() ? id.get<std::string>() : id.dump(), std::move(attributes), std::move(polygons)),
                  index, path, seen, out);
    }
  } catch (const nlohmann::json::exception& e) {
    bad(Status::BadFormat, "footprints: '" + path + "' is marked as hsr's own footprint file but is not one (" + e.what() + ")");
  }
  return out;
}

}  // namespace

FootprintSet read_footprints(const std::string& path, const FootprintReadParams& params) {
  std::error_code ec;
  if (!fs::exists(path, ec)) bad(Status::FileNotFound, "footprints: '" + path + "' not found");
  if (std::optional<FootprintSet> own = read_own_footprints(path, params)) return *own;
  city_gdal::RawLayer layer = module_function<HsrGdalReadFootprints>("gdal", "hsr_gdal_read_footprints")(path, params);
  FootprintSet out;
  out.crs = std::move(layer.crs);
  out.crs_note = std::move(layer.crs_note);
  out.crs_compared = layer.crs_compared;
  std::map<std::string, std::size_t> seen;
  std::size_t index = 0;
  for (city_gdal::RawFeature& raw : layer.features)
    add_feature(feature_of_rings(std::move(raw.id), std::move(raw.attributes), std::move(raw.polygons)), ++index, path, seen, out);
  return out;
}

void write_footprints(const std::string& path, const std::vector<FootprintFeature>& features, const std::string& crs,
                      const std::string& layer) {
  module_function<HsrGdalWriteFootprints>("gdal", "hsr_gdal_write_footprints")(path, features, crs, layer);
}

std::string crs_epsg_code(const std::string& crs) {
  return module_function<HsrGdalCrsEpsgCode>("gdal", "hsr_gdal_crs_epsg_code")(crs);
}

double crs_metres_per_unit(const std::string& crs, bool* projected, std::string* unit) {
  return module_function<HsrGdalCrsMetresPerUnit>("gdal", "hsr_gdal_crs_metres_per_unit")(crs, projected, unit);
}

nlohmann::json footprint_geojson(const FootprintFeature& f) {
  nlohmann::json polygons = nlohmann::json::array();
  auto ring_json = [](const std::vector<Vec2>& ring) {
    nlohmann::json r = nlohmann::json::array();
    for (const Vec2& p : ring) r.push_back({p.x(), p.y()});
    r.push_back({ring.front().x(), ring.front().y()});
    return r;
  };
  for (const FootprintPolygon& p : f.footprint) {
    nlohmann::json rings = nlohmann::json::array({ring_json(p.outer)});
    for (const auto& h : p.holes) rings.push_back(ring_json(h));
    polygons.push_back(std::move(rings));
  }
  nlohmann::json feature = {{"type", "Feature"},
                            {"id", f.id},
                            {"properties", f.attributes},
                            {"geometry", {{"type", "MultiPolygon"}, {"coordinates", polygons}}}};
  return {{"type", "FeatureCollection"}, {kOwnFootprintMember, 1}, {"features", nlohmann::json::array({feature})}};
}

}  // namespace hsr
