// Earth-centred coordinates through GDAL/PROJ (crs_gdal.h), built into the module libhsr_gdal.so.
#include "tiles3d/crs_gdal.h"

#include "core/error.h"

#include <ogr_spatialref.h>

#include <memory>

using namespace hsr;

tiles3d_gdal::EarthPlace hsr_gdal_earth_place(const Vec3& centre, const std::string& crs) {
  const auto bad = [](const std::string& what) { throw Error(Status::BadInput, "tiles3d", what); };
  OGRSpatialReference from, ecef, geographic;
  if (from.SetFromUserInput(crs.c_str()) != OGRERR_NONE) bad("unknown CRS " + crs);
  ecef.importFromEPSG(4978);
  geographic.importFromEPSG(4326);
  for (OGRSpatialReference* s : {&from, &ecef, &geographic}) s->SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  std::shared_ptr<OGRCoordinateTransformation> to_ecef(OGRCreateCoordinateTransformation(&from, &ecef));
  std::unique_ptr<OGRCoordinateTransformation> to_geo(OGRCreateCoordinateTransformation(&from, &geographic));
  tiles3d_gdal::EarthPlace place;
  place.lon = centre.x();
  place.lat = centre.y();
  double h = centre.z();
  double x = centre.x(), y = centre.y(), z = centre.z();
  if (!to_ecef || !to_geo || !to_geo->Transform(1, &place.lon, &place.lat, &h) || !to_ecef->Transform(1, &x, &y, &z))
    bad("cannot bring " + crs + " to earth-centred coordinates (EPSG:4978); give --local");
  place.ecef = Vec3(x, y, z);
  place.to_ecef = [to_ecef](double& px, double& py, double& pz) { return to_ecef->Transform(1, &px, &py, &pz) != 0; };
  return place;
}
