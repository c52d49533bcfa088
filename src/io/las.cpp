// LAS 1.0–1.4 reader, uncompressed and LAZ (LASzip-compressed, COPC included: laz.cpp). From the public
// header: version, header size, offset to point data, point data format and record length, point count
// (legacy 32-bit, or the 64-bit count of LAS 1.4), scale and offset, the (extended) variable length records.
// A point is X*scale + offset per axis; X, Y, Z are the first three int32 of every point record in all
// formats. Per point the attributes later stages use are kept (PointAttributes: classification, return
// number and count, intensity, GPS time, RGB where the format has them), decoded by one record parser,
// append_attributes(), for every format 0–10 (ASPRS LAS 1.4 R15, tables 7–17), whether the records come
// from the file or from the LAZ decoder. The CRS comes from the LASF_Projection records: OGC WKT (record
// 2112) or the GeoTIFF key directory (34735: ProjectedCSTypeGeoKey 3072, else GeographicTypeGeoKey 2048,
// as "EPSG:N"). The points are streamed in runs (stream_las: io.h read_point_chunks, for readers that keep only
// part of a tile); read_las joins the runs into one cloud, so both go through the same decoder and parser.
#include "io/las_internal.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>

namespace hsr::io_detail {

namespace {

/// Byte offsets of the attributes in a point record of format `format` (LAS 1.4 R15): -1 where the format
/// has no such field.
struct LasLayout {
  bool extended = false;  ///< formats 6-10: 4-bit return fields, a full classification byte
  int gps_time = -1;
  int rgb = -1;
};

LasLayout las_layout(int format) {
  LasLayout l;
  l.extended = format >= 6;
  if (format == 1 || format == 3 || format == 4 || format == 5) l.gps_time = 20;
  if (format == 2) l.rgb = 20;
  if (format == 3 || format == 5) l.rgb = 28;
  if (format >= 6) l.gps_time = 22;
  if (format == 7 || format == 8 || format == 10) l.rgb = 30;
  return l;
}

void reserve_attributes(PointAttributes& a, const LasLayout& l, std::uint64_t n) {
  a.classification.reserve(n);
  a.return_number.reserve(n);
  a.number_of_returns.reserve(n);
  a.intensity.reserve(n);
  if (l.gps_time >= 0) a.gps_time.reserve(n);
  if (l.rgb >= 0) a.rgb.reserve(n);
}

/// Appends the attributes of one point record to `a`.
void append_attributes(const unsigned char* r, const LasLayout& l, PointAttributes& a) {
  a.intensity.push_back(load_scalar<std::uint16_t>(r + 12, true));
  if (l.extended) {
    a.return_number.push_back(r[14] & 0x0F);
    a.number_of_returns.push_back(static_cast<std::uint8_t>(r[14] >> 4));
    a.classification.push_back(r[16]);
  } else {
    a.return_number.push_back(r[14] & 0x07);
    a.number_of_returns.push_back(static_cast<std::uint8_t>((r[14] >> 3) & 0x07));
    a.classification.push_back(r[15] & 0x1F);
  }
  if (l.gps_time >= 0) a.gps_time.push_back(load_scalar<double>(r + l.gps_time, true));
  if (l.rgb >= 0)
    a.rgb.push_back({load_scalar<std::uint16_t>(r + l.rgb, true), load_scalar<std::uint16_t>(r + l.rgb + 2, true),
                     load_scalar<std::uint16_t>(r + l.rgb + 4, true)});
}

/// Appends every field of `from` to the same field of `into` (a stream's chunks, one after the other).
void append_attribute_runs(PointAttributes& into, const PointAttributes& from) {
  const auto append = [](auto& a, const auto& b) { a.insert(a.end(), b.begin(), b.end()); };
  append(into.classification, from.classification);
  append(into.return_number, from.return_number);
  append(into.number_of_returns, from.number_of_returns);
  append(into.intensity, from.intensity);
  append(into.gps_time, from.gps_time);
  append(into.rgb, from.rgb);
}

/// Records per block read from an uncompressed file by read_las (and per chunk handed on).
constexpr std::size_t kLasBlock = std::size_t{1} << 16;

/// "EPSG:N" from a GeoTIFF GeoKeyDirectoryTag (u16 words), or "" when it names no EPSG code.
std::string crs_from_geokeys(const std::string& payload) {
  const std::size_t words = payload.size() / 2;
  const auto word = [&](std::size_t i) { return load_scalar<std::uint16_t>(reinterpret_cast<const unsigned char*>(payload.data()) + 2 * i, true); };
  if (words < 4) return "";
  const std::size_t keys = word(3);
  std::uint16_t projected = 0, geographic = 0;
  for (std::size_t k = 0; k < keys && 4 + 4 * k + 3 < words; ++k) {
    const std::size_t at = 4 + 4 * k;
    if (word(at + 1) != 0 || word(at + 2) != 1) continue;  // the value is not stored inline
    if (word(at) == 3072) projected = word(at + 3);
    if (word(at) == 2048) geographic = word(at + 3);
  }
  const std::uint16_t code = (projected != 0 && projected != 32767) ? projected : geographic;
  return (code != 0 && code != 32767) ? "EPSG:" + std::to_string(code) : "";
}

/// The (extended) variable length records the reader needs: the CRS (WKT, GeoTIFF keys) and LASzip's.
struct LasRecords {
  std::string wkt, geokeys;
  std::string laszip;  ///< payload of "laszip encoded" record 22204
  bool has_laszip = false;
};

/// Scans the VLRs and EVLRs. A record that runs past the file's end ends the scan (the CRS is information,
/// not geometry; a LAZ file without its LASzip record is reported by the caller).
LasRecords read_las_records(std::ifstream& in, const LasHeader& h) {
  LasRecords out;
  const auto visit = [&](std::uint64_t at, bool extended) -> std::uint64_t {
    const std::size_t head = extended ? 60 : 54;
    if (at + head > h.file_size) return 0;
    unsigned char r[60] = {};
    in.clear();
    in.seekg(static_cast<std::streamoff>(at));
    in.read(reinterpret_cast<char*>(r), static_cast<std::streamsize>(head));
    if (static_cast<std::size_t>(in.gcount()) != head) return 0;
    const std::string user(reinterpret_cast<const char*>(r + 2), strnlen(reinterpret_cast<const char*>(r + 2), 16));
    const std::uint16_t id = load_scalar<std::uint16_t>(r + 18, true);
    const std::uint64_t length = extended ? load_scalar<std::uint64_t>(r + 20, true) : load_scalar<std::uint16_t>(r + 20, true);
    if (length > h.file_size || at + head + length > h.file_size) return 0;
    std::string* keep = nullptr;
    if (user == "LASF_Projection" && id == 2112) keep = &out.wkt;
    if (user == "LASF_Projection" && id == 34735) keep = &out.geokeys;
    if (user == "laszip encoded" && id == 22204) keep = &out.laszip;
    if (keep != nullptr && length < (1u << 20)) {
      std::string payload(length, '\0');
      in.read(payload.data(), static_cast<std::streamsize>(length));
      if (static_cast<std::uint64_t>(in.gcount()) == length) {
        *keep = std::move(payload);
        if (keep == &out.laszip) out.has_laszip = true;
      }
    }
    return at + head + length;
  };
  std::uint64_t at = h.header_size;
  for (std::uint32_t i = 0; i < h.vlr_count && at != 0; ++i) at = visit(at, false);
  at = h.evlr_start;
  for (std::uint32_t i = 0; i < h.evlr_count && at != 0; ++i) at = visit(at, true);
  return out;
}

std::string crs_of(LasRecords& r) {
  std::string& wkt = r.wkt;
  while (!wkt.empty() && (wkt.back() == '\0' || std::isspace(static_cast<unsigned char>(wkt.back())))) wkt.pop_back();
  return !wkt.empty() ? wkt : crs_from_geokeys(r.geokeys);
}

/// The public header block, checked: signature, version, format, record length, scale, offsets and (for
/// uncompressed files) that the records fit in the file.
LasHeader read_las_header(const std::string& path, std::ifstream& in, std::uint64_t file_size) {
  unsigned char h[375] = {};
  in.read(reinterpret_cast<char*>(h), sizeof(h));
  const std::size_t got = static_cast<std::size_t>(in.gcount());
  if (got < 227 || std::memcmp(h, "LASF", 4) != 0) fail(Status::BadFormat, path, "bad LAS header (no 'LASF' signature or shorter than 227 bytes)");
  const int major = h[24];
  LasHeader l;
  l.minor = h[25];
  l.file_size = file_size;
  if (major != 1 || l.minor > 4)
    fail(Status::BadFormat, path, "unsupported LAS version " + std::to_string(major) + "." + std::to_string(l.minor));
  const auto u16 = [&](std::size_t at) { return load_scalar<std::uint16_t>(h + at, true); };
  const auto u32 = [&](std::size_t at) { return load_scalar<std::uint32_t>(h + at, true); };
  const auto f64 = [&](std::size_t at) { return load_scalar<double>(h + at, true); };
  l.header_size = u16(94);
  l.point_offset = u32(96);
  l.vlr_count = u32(100);
  l.format_byte = h[104];
  l.record_length = u16(105);
  l.count = u32(107);
  l.scale = Vec3(f64(131), f64(139), f64(147));
  l.offset = Vec3(f64(155), f64(163), f64(171));
  l.max = Vec3(f64(179), f64(195), f64(211));
  l.min = Vec3(f64(187), f64(203), f64(219));
  if (l.minor >= 4 && l.header_size >= 375 && got >= 255) {
    const std::uint64_t count64 = load_scalar<std::uint64_t>(h + 247, true);
    if (count64 != 0) l.count = count64;
    l.evlr_start = load_scalar<std::uint64_t>(h + 235, true);
    l.evlr_count = load_scalar<std::uint32_t>(h + 243, true);
  }
  // LASzip marks compressed records by setting bit 7 of the format (bit 6 in files of early writers).
  l.compressed = (l.format_byte & 0xC0) != 0;
  l.format = l.format_byte & 0x3F;
  // Minimum record length per point data format (ASPRS LAS 1.4 R15, table per format).
  static const int min_length[11] = {20, 28, 26, 34, 57, 63, 30, 36, 38, 59, 67};
  if (l.format > 10) fail(Status::BadFormat, path, "unsupported LAS point data format " + std::to_string(l.format));
  if (l.record_length < min_length[l.format])
    fail(Status::BadFormat, path, "LAS record length " + std::to_string(l.record_length) + " too short for point format " + std::to_string(l.format));
  for (int k = 0; k < 3; ++k)
    if (!(l.scale[k] != 0.0) || !std::isfinite(l.scale[k]) || !std::isfinite(l.offset[k]))
      fail(Status::BadFormat, path, "bad LAS header: invalid scale or offset");
  if (l.point_offset < l.header_size || l.point_offset < 227) fail(Status::BadFormat, path, "bad LAS header: offset to point data inside the header");
  if (!l.compressed &&
      static_cast<long double>(l.point_offset) + static_cast<long double>(l.count) * l.record_length > static_cast<long double>(file_size))
    fail(Status::BadFormat, path, "LAS file is truncated: header declares " + std::to_string(l.count) + " points of " +
                                      std::to_string(l.record_length) + " bytes, file is " + std::to_string(file_size) + " bytes");
  // A compressed point needs at least a bit; more points than bits in the file is a lie (and must not
  // reserve memory for them).
  if (l.compressed && static_cast<long double>(l.count) > 8.0L * static_cast<long double>(file_size))
    fail(Status::BadFormat, path, "LAZ file is truncated (or its header wrong): the header declares " + std::to_string(l.count) +
                                      " points, more than a file of " + std::to_string(file_size) + " bytes can hold");
  return l;
}

/// Appends decoded point records (`n` records of h.record_length bytes) to `chunk`: coordinates (scale and
/// offset applied) and attributes.
void append_records(const unsigned char* records, std::size_t n, const LasHeader& h, const LasLayout& layout, PointChunk& chunk) {
  for (std::size_t i = 0; i < n; ++i) {
    const unsigned char* r = records + i * h.record_length;
    Vec3 p;
    for (int k = 0; k < 3; ++k) p[k] = load_scalar<std::int32_t>(r + 4 * k, true) * h.scale[k] + h.offset[k];
    chunk.points.push_back(p);
    append_attributes(r, layout, chunk.attributes);
  }
}

/// The parts of an uncompressed file: runs of kLasPartPoints records.
std::vector<PointPart> plain_parts(const LasHeader& h) {
  std::vector<PointPart> parts;
  for (std::uint64_t first = 0; first < h.count; first += kLasPartPoints) parts.push_back({first, std::min(kLasPartPoints, h.count - first)});
  return parts;
}

/// The records of an uncompressed file, part by part (plain_parts; `wanted` null: all, else the parts it
/// names, the others seeked over), read in blocks of at most `block` records, each handed to `sink` with the
/// file index of its first record.
void read_plain_records(const std::string& path, std::ifstream& in, const LasHeader& h, std::uint64_t block,
                        const std::function<void(std::uint64_t, const unsigned char*, std::size_t)>& sink,
                        const std::vector<char>* wanted) {
  const std::vector<PointPart> parts = plain_parts(h);
  if (wanted && wanted->size() != parts.size())
    fail(Status::Internal, path, "asked for " + std::to_string(wanted->size()) + " parts of a file of " + std::to_string(parts.size()));
  // Never more than the points declared (which the file size bounds): a record length of 65535 bytes with
  // no points must not allocate 65536 records (4 GB; found by fuzz/fuzz_las).
  const std::uint64_t chunk = std::min<std::uint64_t>({block, kLasPartPoints, std::max<std::uint64_t>(h.count, 1)});
  std::vector<unsigned char> buf(chunk * h.record_length);
  bool positioned = false;  // the stream stands at the next part's first record
  for (std::size_t i = 0; i < parts.size(); ++i) {
    if (wanted && !(*wanted)[i]) {
      positioned = false;
      continue;
    }
    if (!positioned) {
      in.clear();
      in.seekg(static_cast<std::streamoff>(h.point_offset + parts[i].first * h.record_length));
    }
    for (std::uint64_t done = 0; done < parts[i].count;) {
      const std::uint64_t n = std::min(chunk, parts[i].count - done);
      in.read(reinterpret_cast<char*>(buf.data()), static_cast<std::streamsize>(n * h.record_length));
      if (static_cast<std::uint64_t>(in.gcount()) != n * h.record_length) fail(Status::BadFormat, path, "LAS point data is truncated");
      sink(parts[i].first + done, buf.data(), n);
      done += n;
    }
    positioned = true;
  }
}

/// The LAS/LAZ file `path` opened for reading, its size in `file_size`; FileNotFound naming it otherwise.
std::ifstream open_las(const std::string& path, std::uint64_t& file_size) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) fail(Status::FileNotFound, path, "file not found or not a regular file");
  file_size = std::filesystem::file_size(path, ec);
  if (ec) fail(Status::FileNotFound, path, "cannot read file size: " + ec.message());
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(Status::FileNotFound, path, "cannot open file for reading");
  return in;
}

}  // namespace

std::string stream_las(const std::string& path, std::size_t chunk_points, const std::function<void(const PointChunk&)>& sink,
                       const std::vector<char>* wanted) {
  if (chunk_points == 0) fail(Status::BadInput, path, "a chunk of the point stream must hold at least one point");
  std::uint64_t file_size = 0;
  std::ifstream in = open_las(path, file_size);
  const LasHeader h = read_las_header(path, in, file_size);
  LasRecords records = read_las_records(in, h);
  if (h.compressed && !records.has_laszip)
    fail(Status::BadFormat, path, "compressed (LAZ) point data without the LASzip record that describes it");
  const LasLayout layout = las_layout(h.format);
  PointChunk chunk;
  std::uint64_t handed = 0;  // points handed on
  // Decoded runs (a LAZ chunk, a block of the plain file) are cut into chunks of at most chunk_points.
  const auto cut = [&](std::uint64_t first, const unsigned char* r, std::size_t n) {
    chunk.first = first;
    for (std::size_t at = 0; at < n;) {
      const std::size_t m = std::min<std::size_t>(chunk_points, n - at);
      chunk.points.clear();
      chunk.attributes = PointAttributes{};
      chunk.points.reserve(m);
      reserve_attributes(chunk.attributes, layout, m);
      append_records(r + at * h.record_length, m, h, layout, chunk);
      sink(chunk);
      chunk.first += m;
      at += m;
    }
    handed += n;
  };
  if (h.compressed) decode_laz(path, in, h, records.laszip, cut, wanted);
  else read_plain_records(path, in, h, chunk_points, cut, wanted);
  if (!wanted && handed != h.count)
    fail(Status::BadFormat, path, "decoded " + std::to_string(handed) + " points, the header declares " + std::to_string(h.count));
  return crs_of(records);
}

std::vector<PointPart> las_parts(const std::string& path) {
  std::uint64_t file_size = 0;
  std::ifstream in = open_las(path, file_size);
  const LasHeader h = read_las_header(path, in, file_size);
  LasRecords records = read_las_records(in, h);
  if (!h.compressed) return plain_parts(h);
  if (!records.has_laszip) fail(Status::BadFormat, path, "compressed (LAZ) point data without the LASzip record that describes it");
  return laz_parts(path, in, h, records.laszip);
}

RawGeometry read_las(const std::string& path) {
  RawGeometry raw;
  raw.always_shift = true;
  // A LAZ header's count is only checked against the chunk table later: reserve no more than a point per
  // byte of the file until then (real LAZ takes several bytes per point).
  const LasHeader h = read_las_header_only(path);
  const std::uint64_t reserve = h.compressed ? std::min<std::uint64_t>(h.count, h.file_size) : h.count;
  raw.points.reserve(reserve);
  reserve_attributes(raw.attributes, las_layout(h.format), reserve);
  raw.crs = stream_las(path, kLasBlock, [&](const PointChunk& c) {
    raw.points.insert(raw.points.end(), c.points.begin(), c.points.end());
    append_attribute_runs(raw.attributes, c.attributes);
  });
  return raw;
}

LasHeader read_las_header_only(const std::string& path) {
  std::uint64_t file_size = 0;
  std::ifstream in = open_las(path, file_size);
  return read_las_header(path, in, file_size);
}

LasHeader read_las_point_records(const std::string& path, std::vector<unsigned char>& records) {
  std::error_code ec;
  const std::uint64_t file_size = std::filesystem::file_size(path, ec);
  if (ec) fail(Status::FileNotFound, path, "cannot read file size: " + ec.message());
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(Status::FileNotFound, path, "cannot open file for reading");
  const LasHeader h = read_las_header(path, in, file_size);
  const LasRecords vlrs = read_las_records(in, h);
  records.clear();
  if (h.compressed) {
    decode_laz(path, in, h, vlrs.laszip,
               [&](std::uint64_t, const unsigned char* r, std::size_t n) { records.insert(records.end(), r, r + n * h.record_length); });
  } else {
    records.resize(h.count * h.record_length);
    in.clear();
    in.seekg(h.point_offset);
    in.read(reinterpret_cast<char*>(records.data()), static_cast<std::streamsize>(records.size()));
    if (static_cast<std::uint64_t>(in.gcount()) != records.size()) fail(Status::BadFormat, path, "LAS point data is truncated");
  }
  return h;
}

}  // namespace hsr::io_detail
