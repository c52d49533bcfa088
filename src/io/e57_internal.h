// Internal to stage io: what the four parts of the E57 reader share (see io/e57.h for the split). Names
// follow ASTM E2807: a file is 1024-byte pages, each 1020 bytes of payload and a CRC-32C; "logical" offsets
// count payload bytes only, "physical" ones count whole pages. Not a public header.
#pragma once

#include "core/module.h"
#include "core/types.h"
#include "io/e57.h"

#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace hsr::io_detail::e57 {

constexpr std::uint64_t kPageBytes = 1024;    ///< physical page size (the only one E2807 files use)
constexpr std::uint64_t kPagePayload = 1020;  ///< logical bytes per page (the last 4 hold the checksum)
constexpr std::size_t kFileHeaderBytes = 48;  ///< the file header at physical offset 0

/// The file header (E2807 §8.4.2).
struct FileHeader {
  std::uint32_t major = 0, minor = 0;
  std::uint64_t physical_length = 0;
  std::uint64_t xml_physical_offset = 0;
  std::uint64_t xml_logical_length = 0;
  std::uint64_t page_size = 0;
};

/// CRC-32C (Castagnoli, reflected, init and final xor 0xFFFFFFFF) of `n` bytes.
std::uint32_t crc32c(const unsigned char* data, std::size_t n);

/// Logical offset of a physical one that is not inside a checksum; UINT64_MAX if it is.
std::uint64_t logical_offset(std::uint64_t physical);
/// Physical offset of a logical one.
std::uint64_t physical_offset(std::uint64_t logical);

/// A file's header and its logical bytes (every page's payload, checksums verified and removed).
struct LogicalFile {
  FileHeader header;
  std::string bytes;
};

/// Checks the header and every page's checksum of the E57 file `path` whose bytes are `file` (consumed).
LogicalFile read_pages(const std::string& path, std::string file);

/// The type of a prototype field (E2807 §8.4.4-8.4.6; String fields are not supported in points).
enum class FieldType { Integer, ScaledInteger, Float };

/// One field of a scan's point prototype, i.e. one bytestream of its compressed vector.
struct Field {
  std::string name;  ///< cartesianX, sphericalRange, intensity, colorRed, rowIndex, ...
  FieldType type = FieldType::Float;
  std::int64_t minimum = INT64_MIN, maximum = INT64_MAX;  ///< Integer / ScaledInteger raw range
  double scale = 1, offset = 0;                             ///< ScaledInteger: value = raw * scale + offset
  bool single = false;                                       ///< Float: 4-byte (single precision) values
  double float_min = 0, float_max = 0;                       ///< Float: the declared bounds, when given
  bool has_float_bounds = false;
};

/// One child of /data3D.
struct Scan {
  std::string name;
  std::array<double, 4> rotation{1, 0, 0, 0};  ///< pose quaternion w, x, y, z (identity when absent)
  Vec3 translation = Vec3::Zero();              ///< pose translation = the scanner's position
  std::uint64_t section_physical_offset = 0;    ///< points' fileOffset: the compressed-vector section
  std::uint64_t records = 0;                    ///< points' recordCount
  std::vector<Field> fields;                    ///< the prototype, in bytestream order
  bool has_intensity_limits = false, has_color_limits = false;
  double intensity_min = 0, intensity_max = 0;  ///< intensityLimits
  double color_min = 0, color_max = 0;          ///< colorLimits (one range for the three channels)
};

/// The scans of /data3D in the XML section `xml`. Throws BadFormat naming `path`. Parsed by Xerces-C in the module
/// libhsr_xml.so (e57_xml.cpp, its entry hsr_xml_parse_e57 below), loaded on first use.
std::vector<Scan> parse_xml(const std::string& path, std::string_view xml, const E57Limits& limits);

/// The decoded values (as double) of the fields of `scan` whose index is in `wanted` (one column per
/// wanted field, in `wanted`'s order, each `scan.records` long), read from the logical bytes of `file`.
std::vector<std::vector<double>> read_columns(const std::string& path, const LogicalFile& file, const Scan& scan,
                                              const std::vector<std::size_t>& wanted);

}  // namespace hsr::io_detail::e57

/// parse_xml's module entry (core/module.h): module "xml", symbol "hsr_xml_parse_e57".
using HsrXmlParseE57 = std::vector<hsr::io_detail::e57::Scan>(const std::string& path, std::string_view xml,
                                                              const hsr::E57Limits& limits);
HSR_MODULE_ENTRY HsrXmlParseE57 hsr_xml_parse_e57;
