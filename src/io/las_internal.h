// Internal to stage io: what the LAS reader (las.cpp) and the LAZ decoder (laz.cpp) share. A LAZ file is a
// LAS file whose point records are compressed; both end in the same record parser, so a LAZ file and its
// LAS twin give the same cloud. Not a public header.
#pragma once

#include "core/types.h"
#include "io/io.h"
#include "io/io_internal.h"

#include <cstdint>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

namespace hsr::io_detail {

/// The public header block fields the readers use (ASPRS LAS 1.4 R15, table 3).
struct LasHeader {
  int minor = 0;                     ///< version 1.minor
  std::uint16_t header_size = 0;
  std::uint32_t point_offset = 0;    ///< offset to point data
  std::uint32_t vlr_count = 0;
  std::uint8_t format_byte = 0;      ///< point data format; LAZ sets bit 7 (and bit 6 for old writers)
  int format = 0;                    ///< format_byte without the compression bits, 0-10
  bool compressed = false;
  std::uint16_t record_length = 0;
  std::uint64_t count = 0;           ///< point records (the 64-bit count of LAS 1.4 when set)
  Vec3 scale = Vec3::Ones(), offset = Vec3::Zero();
  std::uint64_t evlr_start = 0;      ///< LAS 1.4: first extended VLR (0: none)
  std::uint32_t evlr_count = 0;
  std::uint64_t file_size = 0;
  /// The header's extent of the points (max and min X, Y, Z, file coordinates); what the writer says, not
  /// checked against the records.
  Vec3 min = Vec3::Zero(), max = Vec3::Zero();
};

/// Streams the point records of a LAZ file: calls `sink(first, records, n)` with the n decoded records of one
/// chunk (each header.record_length bytes, exactly the bytes the uncompressed LAS file would hold; `first` the
/// file index of the chunk's first point), in file order, chunk after chunk. `laszip` is the payload of the
/// "laszip encoded" VLR (record 22204). `wanted` (null: every chunk): one entry per chunk (laz_parts' order);
/// a chunk not wanted is neither read nor decoded. Chunks are decoded in parallel (TBB, at most HSR_THREADS
/// threads); the order they are handed on does not depend on it. Throws BadFormat naming `path` for anything
/// malformed (unknown compressor or item, broken chunk table, a chunk that decodes short or past its bytes,
/// counts that disagree).
void decode_laz(const std::string& path, std::ifstream& in, const LasHeader& header, const std::string& laszip,
                const std::function<void(std::uint64_t, const unsigned char*, std::size_t)>& sink,
                const std::vector<char>* wanted = nullptr);

/// The chunks of a LAZ file as parts (io.h point_parts): its chunk table read, no point decoded.
std::vector<PointPart> laz_parts(const std::string& path, std::ifstream& in, const LasHeader& header, const std::string& laszip);

/// Streams the points of the LAS or LAZ file `path` in file order: calls `sink` with runs of at most
/// `chunk_points` consecutive points of one part (file coordinates, attributes as read_points keeps them;
/// chunk.first the index of the run's first point). `wanted` (null: all): one entry per part of las_parts;
/// the parts not wanted are skipped (a LAZ chunk not decoded, LAS records seeked over). Memory: one run, and
/// for LAZ one batch of decoded chunks. Returns the file's CRS (PointCloud::crs). Throws BadFormat naming
/// `path` as read_points does, after the runs before the fault were handed on.
std::string stream_las(const std::string& path, std::size_t chunk_points, const std::function<void(const PointChunk&)>& sink,
                       const std::vector<char>* wanted = nullptr);

/// The parts of the LAS or LAZ file `path` (io.h point_parts).
std::vector<PointPart> las_parts(const std::string& path);

/// The checked public header of the LAS or LAZ file `path` (no point is read).
LasHeader read_las_header_only(const std::string& path);

}  // namespace hsr::io_detail

namespace hsr::io_detail {

/// The header of the LAS or LAZ file `path` and all its point records as the uncompressed file would
/// hold them (count * record_length bytes). For tests and benchmarks: read_points() is the reader.
LasHeader read_las_point_records(const std::string& path, std::vector<unsigned char>& records);

}  // namespace hsr::io_detail
