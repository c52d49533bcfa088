// E57 reader (ASTM E2807): the physical pages (e57_pages.cpp), the XML (e57_xml.cpp), each scan's compressed
// vector (e57_vector.cpp), then every scan's points turned by its pose (rotation quaternion, translation)
// into the file's frame and joined in scan order into one cloud. Each scan's pose translation is its
// scanner's position. Points marked invalid (cartesianInvalidState or sphericalInvalidState other than 0:
// no return, or a direction without a range) are dropped. Intensity and colour are kept, scaled from the
// scan's intensityLimits / colorLimits (else the field's declared bounds) to 0-65535, when every scan has them.
#include "io/e57_internal.h"
#include "io/io_internal.h"

#include "core/log.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>

namespace hsr::io_detail {

namespace {

using e57::Field;
using e57::FieldType;
using e57::Scan;

/// Index of the prototype field `name`, or -1.
int e57_field_index(const Scan& s, std::string_view name) {
  for (std::size_t i = 0; i < s.fields.size(); ++i)
    if (s.fields[i].name == name) return static_cast<int>(i);
  return -1;
}

/// The range a field's values are scaled from: the scan's limits when given, else the field's bounds.
bool e57_value_range(const Field& f, bool has_limits, double lo, double hi, double& out_lo, double& out_hi) {
  if (has_limits) { out_lo = lo; out_hi = hi; return true; }
  if (f.type == FieldType::Float) { out_lo = f.float_min; out_hi = f.float_max; return f.has_float_bounds; }
  const double s = f.type == FieldType::ScaledInteger ? f.scale : 1.0, o = f.type == FieldType::ScaledInteger ? f.offset : 0.0;
  out_lo = double(f.minimum) * s + o;
  out_hi = double(f.maximum) * s + o;
  if (out_lo > out_hi) std::swap(out_lo, out_hi);
  return true;
}

/// A value scaled from [lo, hi] to 0-65535 (0 when the range is empty or the value is not finite).
std::uint16_t e57_to_u16(double v, double lo, double hi) {
  if (!(hi > lo) || !std::isfinite(v)) return 0;
  const double t = std::clamp((v - lo) / (hi - lo), 0.0, 1.0);
  return static_cast<std::uint16_t>(std::lround(t * 65535.0));
}

/// The rotation of a pose quaternion (w, x, y, z), normalised unless it already has unit length.
Eigen::Matrix3d e57_rotation(const std::string& path, const Scan& s) {
  Eigen::Quaterniond q(s.rotation[0], s.rotation[1], s.rotation[2], s.rotation[3]);
  const double norm = q.norm();
  if (!(norm > 1e-12) || !std::isfinite(norm)) fail(Status::BadFormat, path, "E57 scan '" + s.name + "': pose rotation is not a quaternion");
  if (norm != 1.0) q.coeffs() /= norm;
  return q.toRotationMatrix();
}

/// Appends one scan's valid points (in the file's frame), intensity and colour.
void e57_append_scan(const std::string& path, const e57::LogicalFile& file, const Scan& s, RawGeometry& raw,
                     bool& all_intensity, bool& all_color) {
  const int cx = e57_field_index(s, "cartesianX"), cy = e57_field_index(s, "cartesianY"), cz = e57_field_index(s, "cartesianZ");
  const int sr = e57_field_index(s, "sphericalRange"), sa = e57_field_index(s, "sphericalAzimuth"),
            se = e57_field_index(s, "sphericalElevation");
  const bool cartesian = cx >= 0 && cy >= 0 && cz >= 0;
  if (!cartesian && !(sr >= 0 && sa >= 0 && se >= 0))
    fail(Status::BadFormat, path, "E57 scan '" + s.name + "': neither cartesianX/Y/Z nor sphericalRange/Azimuth/Elevation");
  const int invalid = e57_field_index(s, cartesian ? "cartesianInvalidState" : "sphericalInvalidState");
  const int in = e57_field_index(s, "intensity");
  const int cr = e57_field_index(s, "colorRed"), cg = e57_field_index(s, "colorGreen"), cb = e57_field_index(s, "colorBlue");
  all_intensity = all_intensity && in >= 0;
  all_color = all_color && cr >= 0 && cg >= 0 && cb >= 0;
  std::vector<std::size_t> wanted;
  for (int i : cartesian ? std::array<int, 3>{cx, cy, cz} : std::array<int, 3>{sr, sa, se}) wanted.push_back(std::size_t(i));
  const std::size_t at_invalid = wanted.size();
  if (invalid >= 0) wanted.push_back(std::size_t(invalid));
  const std::size_t at_intensity = wanted.size();
  if (all_intensity) wanted.push_back(std::size_t(in));
  const std::size_t at_color = wanted.size();
  if (all_color) for (int i : {cr, cg, cb}) wanted.push_back(std::size_t(i));
  const std::vector<std::vector<double>> col = e57::read_columns(path, file, s, wanted);

  double ilo = 0, ihi = 0, clo = 0, chi = 0;
  if (all_intensity && !e57_value_range(s.fields[std::size_t(in)], s.has_intensity_limits, s.intensity_min, s.intensity_max, ilo, ihi)) {
    ilo = 0;  // a Float intensity without bounds: E2807's usual normalised 0-1
    ihi = 1;
  }
  if (all_color && !e57_value_range(s.fields[std::size_t(cr)], s.has_color_limits, s.color_min, s.color_max, clo, chi)) {
    clo = 0;
    chi = 1;
  }
  const Eigen::Matrix3d R = e57_rotation(path, s);
  for (std::uint64_t r = 0; r < s.records; ++r) {
    if (invalid >= 0 && col[at_invalid][r] != 0) continue;
    Vec3 p(col[0][r], col[1][r], col[2][r]);
    if (!cartesian) {  // range, azimuth from +x towards +y, elevation from the xy plane (E2807 §8.4.10)
      const double range = p[0], az = p[1], el = p[2];
      p = Vec3(range * std::cos(el) * std::cos(az), range * std::cos(el) * std::sin(az), range * std::sin(el));
    }
    raw.points.push_back(R * p + s.translation);
    if (all_intensity) raw.attributes.intensity.push_back(e57_to_u16(col[at_intensity][r], ilo, ihi));
    if (all_color)
      raw.attributes.rgb.push_back({e57_to_u16(col[at_color][r], clo, chi), e57_to_u16(col[at_color + 1][r], clo, chi),
                                    e57_to_u16(col[at_color + 2][r], clo, chi)});
  }
}

}  // namespace

std::vector<Scan> e57::parse_xml(const std::string& path, std::string_view xml, const E57Limits& limits) {
  return module_function<HsrXmlParseE57>("xml", "hsr_xml_parse_e57")(path, xml, limits);
}

RawGeometry read_e57(const std::string& path, const E57Limits& limits) {
  const e57::LogicalFile file = e57::read_pages(path, read_whole_file(path));
  const auto xml_start = static_cast<std::size_t>(e57::logical_offset(file.header.xml_physical_offset));
  const std::vector<Scan> scans =
      e57::parse_xml(path, std::string_view(file.bytes).substr(xml_start, file.header.xml_logical_length), limits);
  std::uint64_t records = 0;
  for (const Scan& s : scans) {
    if (s.records > limits.max_points - records)
      fail(Status::BadFormat, path, "E57 file of more than " + std::to_string(limits.max_points) + " points (E57Limits::max_points)");
    records += s.records;
  }
  RawGeometry raw;
  bool all_intensity = true, all_color = true;
  for (const Scan& s : scans) {
    const bool had_intensity = all_intensity, had_color = all_color;
    e57_append_scan(path, file, s, raw, all_intensity, all_color);
    // A scan without intensity (colour) drops that field for the whole file: one value per point or none.
    if (had_intensity && !all_intensity && !raw.attributes.intensity.empty()) {
      log::warn("'" + path + "': E57 scan '" + s.name + "' has no intensity; the file's intensity is dropped");
      raw.attributes.intensity.clear();
    }
    if (had_color && !all_color && !raw.attributes.rgb.empty()) {
      log::warn("'" + path + "': E57 scan '" + s.name + "' has no colour; the file's colour is dropped");
      raw.attributes.rgb.clear();
    }
    if (!s.translation.allFinite()) fail(Status::BadFormat, path, "E57 scan '" + s.name + "': pose translation is not finite");
    raw.scanners.push_back(s.translation);
  }
  return raw;
}

}  // namespace hsr::io_detail
