// E57 (ASTM E2807) point clouds: the limits the reader keeps on untrusted files, and what it reads beside the
// points (each scan's scanner position). The reader is ours (Debian 12 has no E57 library): e57_pages.cpp
// (the physical file: 1024-byte pages with CRC-32C, the header, logical <-> physical offsets), e57_xml.cpp
// (the XML section, parsed with Xerces-C, into scans), e57_vector.cpp (the compressed-vector binary
// sections: data packets, bytestreams, bit-packed integers, scaled integers, floats), e57.cpp (every scan
// turned by its pose into one cloud). read_points() reads .e57 files through it; docs/guide/formats.md says
// what is supported.
#pragma once

#include <cstddef>
#include <cstdint>

namespace hsr {

/// Bounds on an E57 file the reader accepts, so a broken or hostile file gives one clear line instead of
/// an allocation of many gigabytes. Each is checked before the memory it guards is allocated.
struct E57Limits {
  /// Points (records) over all scans of the file.
  std::uint64_t max_points = 1'000'000'000;
  /// Bytes of the XML section (a real file's XML is a few kilobytes per scan).
  std::uint64_t max_xml_bytes = 64ull << 20;
  /// Scans (children of /data3D).
  std::size_t max_scans = 100'000;
  /// Fields of one scan's point prototype (bytestreams of its compressed vector).
  std::size_t max_fields = 256;
};

}  // namespace hsr
