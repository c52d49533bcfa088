// LAS 1.0–1.4 reader (uncompressed). Only the public header fields needed for coordinates are read:
// version, header size, offset to point data, point data format and record length, point count (legacy
// 32-bit, or the 64-bit count of LAS 1.4), scale and offset. A point is X*scale + offset per axis; X, Y, Z
// are the first three int32 of every point record in all formats.
#include "io/io_internal.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>

namespace hsr::io_detail {

RawGeometry read_las(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) fail(Status::FileNotFound, path, "file not found or not a regular file");
  const std::uint64_t file_size = std::filesystem::file_size(path, ec);
  if (ec) fail(Status::FileNotFound, path, "cannot read file size: " + ec.message());
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(Status::FileNotFound, path, "cannot open file for reading");

  unsigned char h[375] = {};
  in.read(reinterpret_cast<char*>(h), sizeof(h));
  const std::size_t got = static_cast<std::size_t>(in.gcount());
  if (got < 227 || std::memcmp(h, "LASF", 4) != 0) fail(Status::BadFormat, path, "bad LAS header (no 'LASF' signature or shorter than 227 bytes)");
  const int major = h[24], minor = h[25];
  if (major != 1 || minor > 4)
    fail(Status::BadFormat, path, "unsupported LAS version " + std::to_string(major) + "." + std::to_string(minor));
  const auto u16 = [&](std::size_t at) { return load_scalar<std::uint16_t>(h + at, true); };
  const auto u32 = [&](std::size_t at) { return load_scalar<std::uint32_t>(h + at, true); };
  const auto f64 = [&](std::size_t at) { return load_scalar<double>(h + at, true); };
  const std::uint16_t header_size = u16(94);
  const std::uint32_t point_offset = u32(96);
  const std::uint8_t format_byte = h[104];
  const std::uint16_t record_length = u16(105);
  std::uint64_t count = u32(107);
  const Vec3 scale(f64(131), f64(139), f64(147));
  const Vec3 offset(f64(155), f64(163), f64(171));
  if (minor >= 4 && header_size >= 375 && got >= 255) {
    const std::uint64_t count64 = load_scalar<std::uint64_t>(h + 247, true);
    if (count64 != 0) count = count64;
  }
  if (format_byte & 0xC0) fail(Status::BadFormat, path, "compressed LAS (LAZ) point data is not supported; decompress it first (e.g. laszip)");
  const int format = format_byte;
  // Minimum record length per point data format (ASPRS LAS 1.4 R15, table per format).
  static const int min_length[11] = {20, 28, 26, 34, 57, 63, 30, 36, 38, 59, 67};
  if (format > 10) fail(Status::BadFormat, path, "unsupported LAS point data format " + std::to_string(format));
  if (record_length < min_length[format])
    fail(Status::BadFormat, path, "LAS record length " + std::to_string(record_length) + " too short for point format " + std::to_string(format));
  for (int k = 0; k < 3; ++k)
    if (!(scale[k] != 0.0) || !std::isfinite(scale[k]) || !std::isfinite(offset[k]))
      fail(Status::BadFormat, path, "bad LAS header: invalid scale or offset");
  if (point_offset < header_size || point_offset < 227) fail(Status::BadFormat, path, "bad LAS header: offset to point data inside the header");
  if (static_cast<long double>(point_offset) + static_cast<long double>(count) * record_length > static_cast<long double>(file_size))
    fail(Status::BadFormat, path, "LAS file is truncated: header declares " + std::to_string(count) + " points of " +
                                      std::to_string(record_length) + " bytes, file is " + std::to_string(file_size) + " bytes");

  RawGeometry raw;
  raw.always_shift = true;
  raw.points.reserve(count);
  in.clear();
  in.seekg(point_offset);
  // Never more than the points declared (which the file size bounds): a record length of 65535 bytes with
  // no points must not allocate 65536 records (4 GB; found by fuzz/fuzz_las).
  const std::uint64_t chunk = std::min<std::uint64_t>(1 << 16, std::max<std::uint64_t>(count, 1));
  std::vector<unsigned char> buf(chunk * record_length);
  for (std::uint64_t done = 0; done < count;) {
    const std::uint64_t n = std::min(chunk, count - done);
    in.read(reinterpret_cast<char*>(buf.data()), static_cast<std::streamsize>(n * record_length));
    if (static_cast<std::uint64_t>(in.gcount()) != n * record_length) fail(Status::BadFormat, path, "LAS point data is truncated");
    for (std::uint64_t i = 0; i < n; ++i) {
      const unsigned char* r = buf.data() + i * record_length;
      Vec3 p;
      for (int k = 0; k < 3; ++k) p[k] = load_scalar<std::int32_t>(r + 4 * k, true) * scale[k] + offset[k];
      raw.points.push_back(p);
    }
    done += n;
  }
  return raw;
}

}  // namespace hsr::io_detail
