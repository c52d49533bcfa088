// Building footprints for `hsr city` and `hsr reconstruct --footprint` (README "City scale"), read and
// written through GDAL/OGR (Debian's libgdal-dev): any OGR vector format by content (GeoPackage, Shapefile,
// GeoJSON, FlatGeobuf, ...), the first layer (or a named one), Polygon and MultiPolygon geometries with
// their holes (curved ones linearised; 2.5D ones flattened), every other geometry skipped with a count.
//
// CRS. The layer's CRS is compared with the points' (a LAS file's WKT or "EPSG:N", or --crs), horizontal
// parts only (a compound CRS's vertical part is ignored): equal, nothing to do; different, the footprints are
// reprojected into the points' CRS (OGR's coordinate transformation, both in GIS axis order: x east, y north)
// and the note says so; either unknown, nothing is checked and the note says that too.
// Ids: the value of `id_field` when given (it must exist), else the feature's FID; they must be unique.
// Attributes: every field of the feature, as JSON (integers, reals, strings; dates and others as their
// string; null fields left out).
#pragma once

#include "core/footprint.h"

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace hsr {

/// One footprint: id, polygons in the points' CRS (global x, y: file coordinates), the feature's fields.
struct FootprintFeature {
  std::string id;
  Footprint footprint;
  nlohmann::json attributes = nlohmann::json::object();
};

struct FootprintReadParams {
  std::string layer;     ///< layer name; "": the first layer
  std::string id_field;  ///< field holding the ids; "": the FIDs
  /// The points' CRS (OGC WKT or "EPSG:N"; "": unknown): the footprints are brought into it.
  std::string points_crs;
};

struct FootprintSet {
  std::vector<FootprintFeature> features;  ///< in layer order
  std::string crs;       ///< the layer's CRS as WKT, or "" (none)
  std::string crs_note;  ///< one line: "same CRS", "reprojected from ... to ...", or why nothing was checked
  bool crs_compared = false;  ///< both CRSs known: the footprints are in the points' CRS (the same, or reprojected)
  std::size_t skipped = 0;  ///< features without a (multi)polygon, or whose rings all had < 3 distinct points
};

/// Reads the footprints of `path`. Throws Error(FileNotFound, "city") for a missing file, Error(BadFormat,
/// "city") for a file OGR cannot open as vectors, a missing layer or id field, duplicate ids, or a
/// reprojection that fails. A file footprint_geojson wrote (its "hsr_footprint" member) is read without GDAL:
/// its polygons are in the points' coordinates (nothing to check or reproject), the same doubles GDAL reads.
/// Any other file is read by GDAL in a child process (child_call.h), which also answers crs_epsg_code and
/// crs_metres_per_unit of `params.points_crs`: this process never maps GDAL.
FootprintSet read_footprints(const std::string& path, const FootprintReadParams& params = {});

/// Writes the features as polygons/multipolygons into a new vector file; the driver by extension (.gpkg
/// GeoPackage, .shp ESRI Shapefile, .geojson/.json GeoJSON, .fgb FlatGeobuf), layer `layer`, CRS `crs`
/// (WKT or "EPSG:N"; "": none), a string field "id" and one field per attribute key of the first feature
/// (integers, reals, strings). Atomic (a temporary file renamed; a Shapefile's side files too).
void write_footprints(const std::string& path, const std::vector<FootprintFeature>& features, const std::string& crs,
                      const std::string& layer = "buildings");

/// "EPSG:N" for a CRS given as WKT or "EPSG:N" when its horizontal part is (or identifies as) an EPSG CRS;
/// the compound code when the whole CRS has one; "" when unknown. This and crs_metres_per_unit are asked of
/// GDAL once per CRS and process, in a child process (with the CRS's code's answers: read_footprints).
std::string crs_epsg_code(const std::string& crs);

/// Metres per unit of a projected CRS's axes (WKT or "EPSG:N"; e.g. 0.3048006 for US survey feet); 1 when
/// the CRS is unknown, or not projected (`projected`, when given, says which).
/// `unit` (when given) receives the unit's name ("metre", "US survey foot").
double crs_metres_per_unit(const std::string& crs, bool* projected = nullptr, std::string* unit = nullptr);

/// One footprint as a GeoJSON FeatureCollection (one Feature, id and properties, a MultiPolygon), coordinates
/// exactly as given (17 significant digits), marked as hsr's own by a member "hsr_footprint": 1 (read_footprints
/// then reads it without GDAL): what `hsr city` hands each building's `hsr reconstruct --footprint`.
nlohmann::json footprint_geojson(const FootprintFeature& feature);

}  // namespace hsr
