// The footprints' GDAL side (footprints_gdal.h), built into the module libhsr_gdal.so.
#include "city/footprints_gdal.h"

#include "city/city_internal.h"
#include "core/error.h"

#include <cpl_conv.h>
#include <cpl_error.h>
#include <gdal_priv.h>
#include <ogr_spatialref.h>
#include <ogrsf_frmts.h>

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>

namespace hsr {

namespace fs = std::filesystem;

namespace {

[[noreturn]] void bad(Status s, const std::string& what) { throw Error(s, kCityStage, what); }

/// GDAL's drivers, once; its messages are kept (CPLGetLastErrorMsg) instead of printed.
void ensure_gdal() {
  static std::once_flag once;
  std::call_once(once, [] {
    GDALAllRegister();
    CPLSetErrorHandler(CPLQuietErrorHandler);
  });
}

std::string gdal_message() {
  const char* m = CPLGetLastErrorMsg();
  return (m && *m) ? std::string(": ") + m : std::string();
}

struct DatasetCloser {
  void operator()(GDALDataset* d) const { GDALClose(d); }
};
using Dataset = std::unique_ptr<GDALDataset, DatasetCloser>;

/// The CRS of `text` (WKT or "EPSG:N"), GIS axis order; false when OGR cannot read it.
bool srs_from(const std::string& text, OGRSpatialReference& srs) {
  if (text.empty()) return false;
  if (srs.SetFromUserInput(text.c_str()) != OGRERR_NONE) return false;
  srs.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  return true;
}

std::string srs_label(const OGRSpatialReference& srs) {
  const char* name = srs.GetAuthorityName(nullptr);
  const char* code = srs.GetAuthorityCode(nullptr);
  if (name && code) return std::string(name) + ":" + code;
  const char* n = srs.GetName();
  return n ? std::string("'") + n + "'" : std::string("an unnamed CRS");
}

/// A ring's corners as stored (the closing repeat included).
std::vector<Vec2> ring_corners(const OGRLinearRing& ring) {
  std::vector<Vec2> corners;
  for (int i = 0; i < ring.getNumPoints(); ++i) corners.emplace_back(ring.getX(i), ring.getY(i));
  return corners;
}

/// A polygon's rings, outer first.
std::vector<std::vector<Vec2>> polygon_rings(const OGRPolygon& poly) {
  std::vector<std::vector<Vec2>> rings;
  const OGRLinearRing* outer = poly.getExteriorRing();
  if (!outer) return rings;
  rings.push_back(ring_corners(*outer));
  for (int h = 0; h < poly.getNumInteriorRings(); ++h) rings.push_back(ring_corners(*poly.getInteriorRing(h)));
  return rings;
}

/// The polygons of a (multi)polygon or collection, curved ones linearised.
void collect_polygons(const OGRGeometry& geometry, std::vector<std::vector<std::vector<Vec2>>>& out) {
  const OGRwkbGeometryType type = wkbFlatten(geometry.getGeometryType());
  if (type == wkbPolygon) {
    out.push_back(polygon_rings(*geometry.toPolygon()));
  } else if (type == wkbMultiPolygon || type == wkbGeometryCollection) {
    for (const OGRGeometry* part : *geometry.toGeometryCollection()) collect_polygons(*part, out);
  } else if (type == wkbCurvePolygon || type == wkbMultiSurface) {
    std::unique_ptr<OGRGeometry> linear(geometry.getLinearGeometry());
    if (linear) collect_polygons(*linear, out);
  }
}

nlohmann::json field_value(const OGRFeature& f, int i) {
  switch (f.GetFieldDefnRef(i)->GetType()) {
    case OFTInteger: return f.GetFieldAsInteger(i);
    case OFTInteger64: return static_cast<std::int64_t>(f.GetFieldAsInteger64(i));
    case OFTReal: return f.GetFieldAsDouble(i);
    default: return std::string(f.GetFieldAsString(i));
  }
}

/// The reprojection from the layer's CRS into the points', or null when none is needed or possible (the
/// note says which; `compared`: both CRSs are known).
std::unique_ptr<OGRCoordinateTransformation> crs_check(OGRLayer& layer, const std::string& points_crs, std::string& note,
                                                       std::string& layer_wkt, bool& compared) {
  const OGRSpatialReference* layer_srs = layer.GetSpatialRef();
  OGRSpatialReference points;
  const bool points_known = srs_from(points_crs, points);
  if (layer_srs) {
    char* wkt = nullptr;
    layer_srs->exportToWkt(&wkt);
    layer_wkt = wkt ? wkt : "";
    CPLFree(wkt);
  }
  compared = layer_srs && points_known;
  if (!compared) {
    note = !layer_srs ? std::string("CRS not checked: the footprints have none")
                      : "CRS not checked: the footprints are in " + srs_label(*layer_srs) + ", the points name no CRS (--crs)";
    return nullptr;
  }
  OGRSpatialReference from(*layer_srs), to(points);
  from.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  if (from.IsCompound()) from.StripVertical();
  if (to.IsCompound()) to.StripVertical();
  const char* options[] = {"IGNORE_DATA_AXIS_TO_SRS_AXIS_MAPPING=YES", "CRITERION=EQUIVALENT", nullptr};
  if (from.IsSame(&to, options)) {
    note = "same CRS as the points (" + srs_label(to) + ")";
    return nullptr;
  }
  std::unique_ptr<OGRCoordinateTransformation> ct(OGRCreateCoordinateTransformation(&from, &to));
  if (!ct) bad(Status::BadFormat, "footprints in " + srs_label(from) + " cannot be reprojected to the points' " + srs_label(to) + gdal_message());
  note = "reprojected from " + srs_label(from) + " to the points' " + srs_label(to);
  return ct;
}

}  // namespace

}  // namespace hsr

using namespace hsr;

hsr::city_gdal::RawLayer hsr_gdal_read_footprints(const std::string& path, const FootprintReadParams& params) {
  ensure_gdal();
  CPLErrorReset();
  Dataset ds(GDALDataset::Open(path.c_str(), GDAL_OF_VECTOR | GDAL_OF_READONLY, nullptr, nullptr, nullptr));
  if (!ds) bad(Status::BadFormat, "footprints: '" + path + "' is not a vector file GDAL can read" + gdal_message());
  if (ds->GetLayerCount() == 0) bad(Status::BadFormat, "footprints: '" + path + "' has no layer");
  OGRLayer* layer = params.layer.empty() ? ds->GetLayer(0) : ds->GetLayerByName(params.layer.c_str());
  if (!layer) bad(Status::BadFormat, "footprints: '" + path + "' has no layer '" + params.layer + "'");
  const int id_index = params.id_field.empty() ? -1 : layer->GetLayerDefn()->GetFieldIndex(params.id_field.c_str());
  if (!params.id_field.empty() && id_index < 0)
    bad(Status::BadFormat, "footprints: '" + path + "' has no field '" + params.id_field + "' (--id-field)");

  city_gdal::RawLayer out;
  const auto ct = crs_check(*layer, params.points_crs, out.crs_note, out.crs, out.crs_compared);
  layer->ResetReading();
  std::size_t index = 0;
  for (auto& feature : *layer) {
    ++index;
    city_gdal::RawFeature f;
    if (id_index >= 0) f.id = feature->GetFieldAsString(id_index);
    else f.id = feature->GetFID() == OGRNullFID ? std::to_string(index) : std::to_string(feature->GetFID());
    for (int i = 0; i < feature->GetFieldCount(); ++i)
      if (feature->IsFieldSetAndNotNull(i)) f.attributes[feature->GetFieldDefnRef(i)->GetNameRef()] = field_value(*feature, i);
    OGRGeometry* geometry = feature->GetGeometryRef();
    if (geometry && ct && geometry->transform(ct.get()) != OGRERR_NONE)
      bad(Status::BadFormat, "footprints: feature " + f.id + " of '" + path + "' cannot be reprojected" + gdal_message());
    if (geometry) collect_polygons(*geometry, f.polygons);
    out.features.push_back(std::move(f));
  }
  return out;
}

void hsr_gdal_write_footprints(const std::string& path, const std::vector<FootprintFeature>& features, const std::string& crs,
                               const std::string& layer_name) {
  ensure_gdal();
  static const std::map<std::string, std::string> drivers = {
      {".gpkg", "GPKG"}, {".shp", "ESRI Shapefile"}, {".geojson", "GeoJSON"}, {".json", "GeoJSON"}, {".fgb", "FlatGeobuf"}};
  const fs::path target(path);
  const auto driver_it = drivers.find(target.extension().string());
  if (driver_it == drivers.end())
    bad(Status::BadInput, "footprints: cannot write '" + path + "' (extensions .gpkg .shp .geojson .json .fgb)");
  GDALDriver* driver = GetGDALDriverManager()->GetDriverByName(driver_it->second.c_str());
  if (!driver) bad(Status::Internal, "footprints: GDAL has no " + driver_it->second + " driver");
  OGRSpatialReference srs;
  const bool has_crs = !crs.empty();
  if (has_crs && !srs_from(crs, srs)) bad(Status::BadInput, "footprints: unknown CRS '" + crs + "'");
  // Written into a fresh folder beside the target, then each file renamed into place: a Shapefile is several.
  const fs::path tmp_dir = target.string() + ".tmp-" + std::to_string(::getpid());
  std::error_code ec;
  fs::remove_all(tmp_dir, ec);
  fs::create_directories(tmp_dir, ec);
  if (ec) bad(Status::FileNotFound, "footprints: cannot create '" + tmp_dir.string() + "': " + ec.message());
  struct Cleanup {
    fs::path dir;
    ~Cleanup() {
      std::error_code e;
      fs::remove_all(dir, e);
    }
  } cleanup{tmp_dir};
  {
    Dataset ds(driver->Create((tmp_dir / target.filename()).string().c_str(), 0, 0, 0, GDT_Unknown, nullptr));
    if (!ds) bad(Status::FileNotFound, "footprints: cannot create '" + path + "'" + gdal_message());
    const char* layer_options[] = {"SIGNIFICANT_FIGURES=17", nullptr};
    OGRLayer* layer = ds->CreateLayer(layer_name.c_str(), has_crs ? &srs : nullptr, wkbMultiPolygon,
                                      driver_it->second == "GeoJSON" ? const_cast<char**>(layer_options) : nullptr);
    if (!layer) bad(Status::Internal, "footprints: cannot create layer '" + layer_name + "'" + gdal_message());
    OGRFieldDefn id_field("id", OFTString);
    layer->CreateField(&id_field);
    std::vector<std::string> keys;
    if (!features.empty())
      for (const auto& [key, value] : features.front().attributes.items()) {
        if (key == "id") continue;
        OGRFieldDefn field(key.c_str(), value.is_number_integer() ? OFTInteger64 : value.is_number() ? OFTReal : OFTString);
        layer->CreateField(&field);
        keys.push_back(key);
      }
    for (const FootprintFeature& f : features) {
      OGRFeature feature(layer->GetLayerDefn());
      feature.SetField("id", f.id.c_str());
      for (const std::string& key : keys) {
        if (!f.attributes.contains(key)) continue;
        const nlohmann::json& v = f.attributes[key];
        if (v.is_number_integer()) feature.SetField(key.c_str(), static_cast<GIntBig>(v.get<std::int64_t>()));
        else if (v.is_number()) feature.SetField(key.c_str(), v.get<double>());
        else feature.SetField(key.c_str(), v.is_string() ? v.get<std::string>().c_str() : v.dump().c_str());
      }
      OGRMultiPolygon multi;
      for (const FootprintPolygon& p : f.footprint) {
        OGRPolygon poly;
        auto add_ring = [&](const std::vector<Vec2>& ring) {
          OGRLinearRing r;
          for (const Vec2& q : ring) r.addPoint(q.x(), q.y());
          r.addPoint(ring.front().x(), ring.front().y());
          poly.addRing(&r);
        };
        add_ring(p.outer);
        for (const auto& h : p.holes) add_ring(h);
        multi.addGeometry(&poly);
      }
      feature.SetGeometry(&multi);
      if (layer->CreateFeature(&feature) != OGRERR_NONE)
        bad(Status::Internal, "footprints: cannot write feature " + f.id + gdal_message());
    }
  }
  for (const auto& entry : fs::directory_iterator(tmp_dir)) {
    fs::rename(entry.path(), target.parent_path().empty() ? entry.path().filename() : target.parent_path() / entry.path().filename(), ec);
    if (ec) bad(Status::FileNotFound, "footprints: cannot write '" + path + "': " + ec.message());
  }
}

std::string hsr_gdal_crs_epsg_code(const std::string& crs) {
  ensure_gdal();
  OGRSpatialReference srs;
  if (!srs_from(crs, srs)) return "";
  auto code_of = [](OGRSpatialReference& s) -> std::string {
    const char* name = s.GetAuthorityName(nullptr);
    const char* code = s.GetAuthorityCode(nullptr);
    if (name && code && std::string(name) == "EPSG") return std::string("EPSG:") + code;
    if (s.AutoIdentifyEPSG() == OGRERR_NONE) {
      name = s.GetAuthorityName(nullptr);
      code = s.GetAuthorityCode(nullptr);
      if (name && code && std::string(name) == "EPSG") return std::string("EPSG:") + code;
    }
    return "";
  };
  std::string code = code_of(srs);
  if (code.empty() && srs.IsCompound()) {
    srs.StripVertical();
    code = code_of(srs);
  }
  return code;
}

double hsr_gdal_crs_metres_per_unit(const std::string& crs, bool* projected, std::string* unit) {
  ensure_gdal();
  if (projected) *projected = false;
  if (unit) *unit = "metre";
  OGRSpatialReference srs;
  if (!srs_from(crs, srs) || !srs.IsProjected()) return 1.0;
  if (projected) *projected = true;
  const char* name = nullptr;
  const double m = srs.GetLinearUnits(&name);
  if (unit && name) *unit = name;
  return m > 0 && std::isfinite(m) ? m : 1.0;
}
