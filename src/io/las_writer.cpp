// LAS 1.2 point format 1 writer (las_writer.h).
#include "io/las_writer.h"

#include "core/atomic_file.h"
#include "io/io_internal.h"

#include <cmath>
#include <cstring>

namespace hsr {

namespace {

using io_detail::store_scalar;

constexpr std::uint16_t kHeaderSize = 227;
constexpr std::uint16_t kRecordLength = 28;

[[noreturn]] void bad(const std::string& path, const std::string& what) { io_detail::fail(Status::BadInput, path, what); }

void put_text(std::string& out, const std::string& text, std::size_t width) {
  std::string field = text.substr(0, width);
  field.resize(width, '\0');
  out += field;
}

/// One variable length record: 54-byte header and payload.
std::string vlr(std::uint16_t record_id, const std::string& payload, const std::string& description) {
  std::string out;
  store_scalar<std::uint16_t>(out, 0, true);  // reserved
  put_text(out, "LASF_Projection", 16);
  store_scalar<std::uint16_t>(out, record_id, true);
  store_scalar<std::uint16_t>(out, static_cast<std::uint16_t>(payload.size()), true);
  put_text(out, description, 32);
  return out + payload;
}

/// GeoKeyDirectoryTag with the model type and the EPSG code.
std::string geokeys(int code) {
  const bool geographic = code >= 4000 && code <= 4999;
  const std::uint16_t words[] = {1, 1, 0, 2,                                             // version, revision, keys
                                 1024, 0, 1, static_cast<std::uint16_t>(geographic ? 2 : 1),  // GTModelTypeGeoKey
                                 static_cast<std::uint16_t>(geographic ? 2048 : 3072), 0, 1, static_cast<std::uint16_t>(code)};
  std::string out;
  for (std::uint16_t w : words) store_scalar<std::uint16_t>(out, w, true);
  return out;
}

/// The CRS record, or "" for none.
std::string crs_record(const std::string& path, const std::string& crs) {
  if (crs.empty()) return "";
  if (crs.size() > 5 && (crs.compare(0, 5, "EPSG:") == 0 || crs.compare(0, 5, "epsg:") == 0)) {
    const std::string digits = crs.substr(5);
    if (digits.empty() || digits.size() > 5 || digits.find_first_not_of("0123456789") != std::string::npos ||
        std::stol(digits) > 65535)
      bad(path, "LAS writer: CRS '" + crs + "' is not EPSG:N with N < 65536");
    return vlr(34735, geokeys(static_cast<int>(std::stol(digits))), "GeoKeyDirectoryTag");
  }
  if (crs.size() + 1 > 65535) bad(path, "LAS writer: the WKT is too long for a LAS 1.2 record");
  return vlr(2112, crs + '\0', "OGC WKT");
}

}  // namespace

void write_las(const std::string& path, const PointCloud& cloud, const LasWriteParams& params) {
  if (cloud.empty()) bad(path, "LAS writer: no point");
  if (!(params.scale > 0) || !std::isfinite(params.scale)) bad(path, "LAS writer: scale must be > 0");
  Vec3 offset = params.offset;
  for (int k = 0; k < 3; ++k)
    if (std::isnan(offset[k])) offset[k] = cloud.origin[k];
  const PointAttributes& a = cloud.attributes;
  const std::string vlrs = crs_record(path, params.crs.empty() ? cloud.crs : params.crs);

  std::string body;
  body.reserve(cloud.size() * kRecordLength);
  std::uint32_t by_return[5] = {0, 0, 0, 0, 0};
  BBox box;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    std::int32_t q[3];
    Vec3 stored;
    for (int k = 0; k < 3; ++k) {
      const double steps = std::round((cloud.points[i][k] + cloud.origin[k] - offset[k]) / params.scale);
      if (!(std::abs(steps) < 2147483647.0)) bad(path, "LAS writer: a coordinate is out of the int32 range at this scale");
      q[k] = static_cast<std::int32_t>(steps);
      stored[k] = q[k] * params.scale + offset[k];
    }
    box.extend(stored);
    const std::uint8_t ret = a.return_number.empty() ? 1 : a.return_number[i];
    const std::uint8_t count = a.number_of_returns.empty() ? 1 : a.number_of_returns[i];
    const std::uint8_t cls = a.classification.empty() ? 0 : a.classification[i];
    if (ret > 7 || count > 7 || cls > 31) bad(path, "LAS writer: a return number or count above 7, or a class above 31");
    if (ret >= 1 && ret <= 5) ++by_return[ret - 1];
    for (int k = 0; k < 3; ++k) store_scalar<std::int32_t>(body, q[k], true);
    store_scalar<std::uint16_t>(body, a.intensity.empty() ? 0 : a.intensity[i], true);
    body += static_cast<char>((ret & 0x07) | ((count & 0x07) << 3));
    body += static_cast<char>(cls);
    body += '\0';  // scan angle rank
    body += '\0';  // user data
    store_scalar<std::uint16_t>(body, 0, true);  // point source id
    store_scalar<double>(body, a.gps_time.empty() ? 0.0 : a.gps_time[i], true);
  }

  std::string h;
  h += "LASF";
  store_scalar<std::uint16_t>(h, 0, true);  // file source id
  store_scalar<std::uint16_t>(h, 0, true);  // global encoding
  h.append(16, '\0');                       // project GUID
  h += static_cast<char>(1);
  h += static_cast<char>(2);
  put_text(h, "hsr", 32);
  put_text(h, "hsr " HSR_VERSION " las_writer", 32);
  store_scalar<std::uint16_t>(h, 0, true);  // creation day and year: unknown (same bytes every run)
  store_scalar<std::uint16_t>(h, 0, true);
  store_scalar<std::uint16_t>(h, kHeaderSize, true);
  store_scalar<std::uint32_t>(h, static_cast<std::uint32_t>(kHeaderSize + vlrs.size()), true);
  store_scalar<std::uint32_t>(h, vlrs.empty() ? 0 : 1, true);
  h += static_cast<char>(1);  // point data format 1
  store_scalar<std::uint16_t>(h, kRecordLength, true);
  if (cloud.size() > 0xFFFFFFFFu) bad(path, "LAS writer: more than 2^32 - 1 points (LAS 1.2)");
  store_scalar<std::uint32_t>(h, static_cast<std::uint32_t>(cloud.size()), true);
  for (std::uint32_t n : by_return) store_scalar<std::uint32_t>(h, n, true);
  for (int k = 0; k < 3; ++k) store_scalar<double>(h, params.scale, true);
  for (int k = 0; k < 3; ++k) store_scalar<double>(h, offset[k], true);
  for (int k = 0; k < 3; ++k) {
    store_scalar<double>(h, box.max[k], true);
    store_scalar<double>(h, box.min[k], true);
  }
  HSR_ASSERT(h.size() == kHeaderSize, "LAS header size");

  AtomicFile file(path, "io");
  file.stream().write(h.data(), static_cast<std::streamsize>(h.size()));
  file.stream().write(vlrs.data(), static_cast<std::streamsize>(vlrs.size()));
  file.stream().write(body.data(), static_cast<std::streamsize>(body.size()));
  file.commit();
}

}  // namespace hsr
