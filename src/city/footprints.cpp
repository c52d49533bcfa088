// Footprints (footprints.h): hsr's own footprint files read here, every other vector file read and written by
// GDAL/OGR in the module libhsr_gdal.so (footprints_gdal.cpp), loaded the first time a footprint needs it. The
// reads and the CRS questions are asked in a child process (child_call.h), so that the module and the ~100
// libraries it maps are never this process's (DECISIONS #245); the writes (synth, tests) load it here.
#include "city/footprints.h"

#include "city/child_call.h"
#include "city/city_internal.h"
#include "city/footprints_gdal.h"
#include "core/error.h"
#include "core/module.h"

#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
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

/// A ring's corners as bytes (the doubles x, y of each, as stored: the same bits back) and back.
nlohmann::json ring_bytes(const std::vector<Vec2>& ring) {
  std::vector<std::uint8_t> bytes(ring.size() * sizeof(Vec2));
  if (!ring.empty()) std::memcpy(bytes.data(), ring.data(), bytes.size());
  return nlohmann::json::binary(std::move(bytes));
}
std::vector<Vec2> ring_of_bytes(const nlohmann::json& j) {
  const std::vector<std::uint8_t>& bytes = j.get_binary();
  std::vector<Vec2> ring(bytes.size() / sizeof(Vec2));
  if (!ring.empty()) std::memcpy(static_cast<void*>(ring.data()), bytes.data(), ring.size() * sizeof(Vec2));
  return ring;
}

/// A layer GDAL read, as call_in_child's plain data, and back.
nlohmann::json layer_json(const city_gdal::RawLayer& layer) {
  nlohmann::json features = nlohmann::json::array();
  for (const city_gdal::RawFeature& f : layer.features) {
    nlohmann::json polygons = nlohmann::json::array();
    for (const auto& rings : f.polygons) {
      nlohmann::json& out = polygons.emplace_back(nlohmann::json::array());
      for (const std::vector<Vec2>& ring : rings) out.push_back(ring_bytes(ring));
    }
    features.push_back({{"id", f.id}, {"attributes", f.attributes}, {"polygons", std::move(polygons)}});
  }
  return {{"features", std::move(features)}, {"crs", layer.crs}, {"crs_note", layer.crs_note}, {"crs_compared", layer.crs_compared}};
}
city_gdal::RawLayer layer_of_json(const nlohmann::json& j) {
  city_gdal::RawLayer layer;
  for (const nlohmann::json& f : j.at("features")) {
    city_gdal::RawFeature& raw = layer.features.emplace_back();
    raw.id = f.at("id").get<std::string>();
    raw.attributes = f.at("attributes");
    for (const nlohmann::json& rings : f.at("polygons")) {
      auto& out = raw.polygons.emplace_back();
      for (const nlohmann::json& ring : rings) out.push_back(ring_of_bytes(ring));
    }
  }
  layer.crs = j.at("crs").get<std::string>();
  layer.crs_note = j.at("crs_note").get<std::string>();
  layer.crs_compared = j.at("crs_compared").get<bool>();
  return layer;
}

/// What crs_epsg_code and crs_metres_per_unit say of one CRS.
struct CrsFacts {
  std::string epsg;
  double metres = 1.0;
  bool projected = false;
  std::string unit;
};

/// The facts of `crs` from the GDAL module (in the process that calls it: call_in_child's child).
nlohmann::json crs_facts_json(const std::string& crs) {
  CrsFacts f;
  f.epsg = module_function<HsrGdalCrsEpsgCode>("gdal", "hsr_gdal_crs_epsg_code")(crs);
  f.metres = module_function<HsrGdalCrsMetresPerUnit>("gdal", "hsr_gdal_crs_metres_per_unit")(crs, &f.projected, &f.unit);
  return {{"epsg", f.epsg}, {"metres", f.metres}, {"projected", f.projected}, {"unit", f.unit}};
}

/// The facts of `crs` and, when it has one, of its EPSG code: the city asks of both (a tile's WKT, then the
/// sequence's "EPSG:N"), so one child answers both. As {crs: facts, ...}.
nlohmann::json crs_facts_with_code(const std::string& crs) {
  nlohmann::json out = {{crs, crs_facts_json(crs)}};
  const std::string code = out[crs].at("epsg").get<std::string>();
  if (!code.empty() && code != crs) out[code] = crs_facts_json(code);
  return out;
}

/// The CRS facts this process has been told, by CRS text. Why: the city driver asks of the same CRS several
/// times per tile (its units, its code, its units again for the LoDs); each child loads GDAL and PROJ anew.
class CrsFactsCache {
 public:
  /// The facts of `crs`, asking a child (crs_facts_with_code) the first time.
  CrsFacts get(const std::string& crs) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!facts_.count(crs)) keep(call_in_child("a CRS's code and units", [&] { return crs_facts_with_code(crs); }));
    return facts_.at(crs);
  }
  bool has(const std::string& crs) {
    std::lock_guard<std::mutex> lock(mutex_);
    return facts_.count(crs) > 0;
  }
  /// Keeps the facts of crs_facts_with_code's answer.
  void add(const nlohmann::json& answer) {
    std::lock_guard<std::mutex> lock(mutex_);
    keep(answer);
  }

 private:
  void keep(const nlohmann::json& answer) {
    for (const auto& [crs, j] : answer.items())
      facts_[crs] = {j.at("epsg").get<std::string>(), j.at("metres").get<double>(), j.at("projected").get<bool>(),
                     j.at("unit").get<std::string>()};
  }
  std::mutex mutex_;
  std::map<std::string, CrsFacts> facts_;
};

CrsFactsCache& crs_facts_cache() {
  static CrsFactsCache cache;
  return cache;
}

/// The layer of `path` read by GDAL in a child (call_in_child), with the facts of the points' CRS when this
/// process has not been told them: the city's tile asks of them too, and the child has GDAL and PROJ loaded.
city_gdal::RawLayer read_gdal_layer(const std::string& path, const FootprintReadParams& params) {
  CrsFactsCache& cache = crs_facts_cache();
  const bool ask_crs = !cache.has(params.points_crs);
  const nlohmann::json answer = call_in_child("footprints: '" + path + "'", [&] {
    nlohmann::json out = {{"layer", layer_json(module_function<HsrGdalReadFootprints>("gdal", "hsr_gdal_read_footprints")(path, params))}};
    if (ask_crs) out["crs_facts"] = crs_facts_with_code(params.points_crs);
    return out;
  });
  if (answer.contains("crs_facts")) cache.add(answer.at("crs_facts"));
  return layer_of_json(answer.at("layer"));
}

}  // namespace

FootprintSet read_footprints(const std::string& path, const FootprintReadParams& params) {
  std::error_code ec;
  if (!fs::exists(path, ec)) bad(Status::FileNotFound, "footprints: '" + path + "' not found");
  if (std::optional<FootprintSet> own = read_own_footprints(path, params)) return *own;
  city_gdal::RawLayer layer = read_gdal_layer(path, params);
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

std::string crs_epsg_code(const std::string& crs) { return crs_facts_cache().get(crs).epsg; }

double crs_metres_per_unit(const std::string& crs, bool* projected, std::string* unit) {
  const CrsFacts f = crs_facts_cache().get(crs);
  if (projected) *projected = f.projected;
  if (unit) *unit = f.unit;
  return f.metres;
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
