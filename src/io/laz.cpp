// LAZ point data (LASzip compressed format; COPC files are LAZ 1.4 files whose chunks are the octree's
// nodes, read here as plain chunks, all of them, in file order). What the "laszip encoded" VLR says:
// compressor (1 pointwise: one stream; 2 pointwise chunked; 3 layered chunked, LAS 1.4), coder (0:
// arithmetic), chunk size (points per chunk, or 0xFFFFFFFF: variable, each chunk's count in the table), and
// the items that make up a record. The point data starts with the chunk table's offset (-1: it is in the
// file's last 8 bytes); the table (version 0, chunk count, then per chunk its point count when variable and
// its byte count, coded by an integer decompressor against the previous chunk's) gives each chunk's bytes.
// A chunk holds its first point raw, then the rest coded (laz_items.h). Decoding yields the exact LAS
// records, which las.cpp parses as it does uncompressed ones.
#include "io/las_internal.h"
#include "io/laz_items.h"

#include "core/threads.h"

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <numeric>

namespace hsr::io_detail {

namespace {

struct LazDescription {
  std::uint16_t compressor = 0, coder = 0;
  std::uint32_t chunk_size = 0;  ///< points per chunk; kVariableChunks: per chunk in the table
  std::vector<laz::Item> items;
};
constexpr std::uint32_t kVariableChunks = 0xFFFFFFFFu;

/// One chunk: where its bytes are and how many points it holds.
struct Chunk {
  std::uint64_t begin = 0, end = 0;
  std::uint64_t points = 0;
  std::uint64_t first = 0;  ///< the index in the file of its first point
};

[[noreturn]] void bad(const std::string& path, const std::string& what) { fail(Status::BadFormat, path, what); }

LazDescription parse_laszip_record(const std::string& path, const std::string& payload, const LasHeader& h) {
  const auto* p = reinterpret_cast<const unsigned char*>(payload.data());
  if (payload.size() < 34) bad(path, "LASzip record too short (" + std::to_string(payload.size()) + " bytes)");
  LazDescription d;
  d.compressor = laz::load_le<std::uint16_t>(p);
  d.coder = laz::load_le<std::uint16_t>(p + 2);
  d.chunk_size = laz::load_le<std::uint32_t>(p + 12);
  const std::uint16_t n = laz::load_le<std::uint16_t>(p + 32);
  if (payload.size() < 34 + 6u * n) bad(path, "LASzip record too short for its " + std::to_string(n) + " items");
  for (std::uint16_t i = 0; i < n; ++i)
    d.items.push_back({laz::load_le<std::uint16_t>(p + 34 + 6 * i), laz::load_le<std::uint16_t>(p + 36 + 6 * i),
                       laz::load_le<std::uint16_t>(p + 38 + 6 * i)});
  if (d.compressor < 1 || d.compressor > 3) bad(path, "unknown LASzip compressor " + std::to_string(d.compressor));
  if (d.coder != 0) bad(path, "unknown LASzip coder " + std::to_string(d.coder));
  if (d.items.empty()) bad(path, "LASzip record lists no items");
  std::size_t total = 0;
  for (const auto& item : d.items) total += item.size;
  if (total != h.record_length)
    bad(path, "LASzip items make " + std::to_string(total) + "-byte records, the header says " + std::to_string(h.record_length));
  const bool layered = d.compressor == 3;
  const std::uint16_t first = layered ? laz::kPoint14 : laz::kPoint10;
  if (d.items[0].type != first)
    bad(path, "LASzip compressor " + std::to_string(d.compressor) + " needs " + (layered ? "POINT14" : "POINT10") +
                  " first, the record lists " + laz::item_name(d.items[0]));
  if (layered != (h.format >= 6))
    bad(path, "LASzip compressor " + std::to_string(d.compressor) + " does not fit point format " + std::to_string(h.format));
  // Each item must be one we decode (checked once here, so chunks need not report it).
  for (const auto& item : d.items) {
    const std::vector<unsigned char> zeros(item.size);
    const bool known = layered ? laz::make_layered_item(item) != nullptr : laz::make_pointwise_item(item, zeros.data()) != nullptr;
    if (!known) bad(path, "unsupported LASzip item " + laz::item_name(item) + " (" + std::to_string(item.size) + " bytes)");
  }
  if (d.compressor != 1 && d.chunk_size == 0) bad(path, "LASzip chunk size 0");
  return d;
}

std::vector<unsigned char> read_bytes(const std::string& path, std::ifstream& in, std::uint64_t at, std::uint64_t n) {
  std::vector<unsigned char> buf(n);
  in.clear();
  in.seekg(static_cast<std::streamoff>(at));
  in.read(reinterpret_cast<char*>(buf.data()), static_cast<std::streamsize>(n));
  if (static_cast<std::uint64_t>(in.gcount()) != n) bad(path, "LAZ file is truncated (cannot read " + std::to_string(n) + " bytes at " + std::to_string(at) + ")");
  return buf;
}

/// Where the point data ends: at the first EVLR when there are any after it, else at the end of the file.
std::uint64_t point_data_end(const LasHeader& h) {
  return (h.evlr_count > 0 && h.evlr_start > h.point_offset && h.evlr_start <= h.file_size) ? h.evlr_start : h.file_size;
}

/// The chunks of a chunked file, from its chunk table, checked against the file and the header's count.
std::vector<Chunk> read_chunk_table(const std::string& path, std::ifstream& in, const LasHeader& h, const LazDescription& d) {
  if (static_cast<std::uint64_t>(h.point_offset) + 8 > h.file_size) bad(path, "LAZ file is truncated: no chunk table offset");
  const std::uint64_t data_begin = h.point_offset + 8ull;
  std::int64_t table_at = laz::load_le<std::int64_t>(read_bytes(path, in, h.point_offset, 8).data());
  if (table_at == -1) {  // written by a streaming compressor: the offset is in the file's last 8 bytes
    if (h.file_size < data_begin + 8) bad(path, "LAZ file is truncated: no chunk table offset at its end");
    table_at = laz::load_le<std::int64_t>(read_bytes(path, in, h.file_size - 8, 8).data());
  }
  if (table_at >= static_cast<std::int64_t>(data_begin) && static_cast<std::uint64_t>(table_at) + 8 > h.file_size &&
      static_cast<std::uint64_t>(table_at) < (std::uint64_t{1} << 40))
    bad(path, "LAZ file is truncated: its chunk table at byte " + std::to_string(table_at) + " lies past its end (" +
                  std::to_string(h.file_size) + " bytes)");
  if (table_at < static_cast<std::int64_t>(data_begin) || static_cast<std::uint64_t>(table_at) + 8 > h.file_size)
    bad(path, "broken LAZ chunk table: its offset " + std::to_string(table_at) + " is outside the file's point data (" +
                  std::to_string(data_begin) + ".." + std::to_string(h.file_size) + ")");
  const auto head = read_bytes(path, in, static_cast<std::uint64_t>(table_at), 8);
  const std::uint32_t version = laz::load_le<std::uint32_t>(head.data());
  const std::uint32_t n = laz::load_le<std::uint32_t>(head.data() + 4);
  if (version != 0) bad(path, "broken LAZ chunk table: version " + std::to_string(version) + " (expected 0)");
  if (n == 0 && h.count > 0) bad(path, "broken LAZ chunk table: no chunks for " + std::to_string(h.count) + " points");
  if (n > h.count) bad(path, "broken LAZ chunk table: " + std::to_string(n) + " chunks for " + std::to_string(h.count) + " points");
  const std::uint64_t table_bytes_at = static_cast<std::uint64_t>(table_at) + 8;
  const auto coded = read_bytes(path, in, table_bytes_at, h.file_size - table_bytes_at);
  laz::ArithmeticDecoder dec(coded.data(), coded.data() + coded.size());
  laz::IntegerDecompressor ic(32, 2);
  const bool variable = d.chunk_size == kVariableChunks;
  std::vector<Chunk> chunks(n);
  std::uint32_t last_points = 0, last_bytes = 0;
  std::uint64_t at = data_begin, points = 0;
  for (std::uint32_t i = 0; i < n; ++i) {
    if (variable) last_points = static_cast<std::uint32_t>(ic.decompress(dec, static_cast<std::int32_t>(last_points), 0));
    last_bytes = static_cast<std::uint32_t>(ic.decompress(dec, static_cast<std::int32_t>(last_bytes), 1));
    Chunk& c = chunks[i];
    c.points = variable ? last_points : std::min<std::uint64_t>(d.chunk_size, h.count - std::min(h.count, points));
    c.begin = at;
    c.end = at + last_bytes;
    if (c.points == 0)
      bad(path, "LAZ chunk table holds chunk " + std::to_string(i) + " of " + std::to_string(n) + " with no points (the header declares " +
                    std::to_string(h.count) + ")");
    if (c.end > static_cast<std::uint64_t>(table_at) || last_bytes == 0)
      bad(path, "broken LAZ chunk table: chunk " + std::to_string(i) + " of " + std::to_string(n) + " (" +
                    std::to_string(last_bytes) + " bytes at " + std::to_string(at) + ") is empty or runs past the table");
    at = c.end;
    points += c.points;
  }
  if (dec.overrun() > 0) bad(path, "broken LAZ chunk table: it is truncated");
  if (points != h.count)
    bad(path, "LAZ chunk table holds " + std::to_string(points) + " points, the header declares " + std::to_string(h.count));
  return chunks;
}

/// Decodes one pointwise chunk (compressor 1 or 2) into `out` (points * record length bytes). Returns ""
/// or what is wrong.
std::string decode_pointwise_chunk(const LazDescription& d, std::size_t record_length, const unsigned char* begin,
                                   const unsigned char* end, std::uint64_t points, std::vector<unsigned char>& out) {
  out.resize(points * record_length);
  if (points == 0) return "";
  if (static_cast<std::size_t>(end - begin) < record_length) return "its first point is cut";
  std::memcpy(out.data(), begin, record_length);
  std::vector<std::unique_ptr<laz::PointwiseItem>> items;
  std::vector<std::size_t> offsets;
  std::size_t offset = 0;
  for (const auto& item : d.items) {
    items.push_back(laz::make_pointwise_item(item, out.data() + offset));
    offsets.push_back(offset);
    offset += item.size;
  }
  laz::ArithmeticDecoder dec(begin + record_length, end);
  for (std::uint64_t i = 1; i < points; ++i) {
    unsigned char* record = out.data() + i * record_length;
    for (std::size_t k = 0; k < items.size(); ++k) items[k]->decode(dec, record + offsets[k]);
    if ((i & 1023) == 0 && dec.overrun() > 0) break;  // a well-formed stream never runs out: stop early
  }
  if (dec.overrun() > 0) return "it decodes past its " + std::to_string(end - begin) + " bytes (truncated or corrupt)";
  return "";
}

/// Decodes one layered chunk (compressor 3): the raw first point, the chunk's point count, every item's
/// layer sizes, then the layers.
std::string decode_layered_chunk(const LazDescription& d, std::size_t record_length, const unsigned char* begin,
                                 const unsigned char* end, std::uint64_t points, std::vector<unsigned char>& out) {
  out.resize(points * record_length);
  if (points == 0) return "";
  const unsigned char* p = begin;
  if (static_cast<std::size_t>(end - p) < record_length + 4) return "its first point is cut";
  std::memcpy(out.data(), p, record_length);
  p += record_length;
  const std::uint32_t count = laz::load_le<std::uint32_t>(p);
  p += 4;
  if (count != points) return "it says " + std::to_string(count) + " points, the chunk table " + std::to_string(points);
  std::vector<std::unique_ptr<laz::LayeredItem>> items;
  std::vector<std::uint32_t> sizes;
  for (const auto& item : d.items) {
    items.push_back(laz::make_layered_item(item));
    for (std::size_t k = 0; k < items.back()->layer_count(); ++k) {
      if (end - p < 4) return "its layer sizes are cut";
      sizes.push_back(laz::load_le<std::uint32_t>(p));
      p += 4;
    }
  }
  const std::uint64_t total = std::accumulate(sizes.begin(), sizes.end(), std::uint64_t{0});
  if (total > static_cast<std::uint64_t>(end - p))
    return "its layers need " + std::to_string(total) + " bytes, it has " + std::to_string(end - p);
  std::size_t next_size = 0, offset = 0;
  const int channel = laz::scanner_channel(out.data());
  for (std::size_t k = 0; k < items.size(); ++k) {
    std::vector<laz::Layer> layers;
    for (std::size_t j = 0; j < items[k]->layer_count(); ++j) {
      layers.push_back({p, p + sizes[next_size]});
      p += sizes[next_size++];
    }
    items[k]->start(out.data() + offset, layers, channel);
    offset += d.items[k].size;
  }
  for (std::uint64_t i = 1; i < points; ++i) {
    unsigned char* record = out.data() + i * record_length;
    int context = 0;
    offset = 0;
    for (std::size_t k = 0; k < items.size(); ++k) {
      items[k]->decode(record + offset, context);
      offset += d.items[k].size;
    }
    if ((i & 1023) == 0 && items[0]->overrun() > 0) break;  // a well-formed stream never runs out: stop early
  }
  for (const auto& item : items)
    if (item->overrun() > 0) return "a layer decodes past its bytes (truncated or corrupt)";
  return "";
}

}  // namespace

namespace {

/// The chunks of the file (compressor 1: the one stream as one chunk), each with its first point's index.
std::vector<Chunk> file_chunks(const std::string& path, std::ifstream& in, const LasHeader& h, const LazDescription& d) {
  std::vector<Chunk> chunks;
  if (d.compressor == 1) {  // one stream, no table
    chunks.push_back({h.point_offset, point_data_end(h), h.count, 0});
  } else {
    chunks = read_chunk_table(path, in, h, d);
  }
  std::uint64_t first = 0;
  for (Chunk& c : chunks) {
    c.first = first;
    first += c.points;
  }
  return chunks;
}

}  // namespace

std::vector<PointPart> laz_parts(const std::string& path, std::ifstream& in, const LasHeader& h, const std::string& laszip) {
  const LazDescription d = parse_laszip_record(path, laszip, h);
  std::vector<PointPart> parts;
  for (const Chunk& c : file_chunks(path, in, h, d)) parts.push_back({c.first, c.points});
  return parts;
}

void decode_laz(const std::string& path, std::ifstream& in, const LasHeader& h, const std::string& laszip,
                const std::function<void(std::uint64_t, const unsigned char*, std::size_t)>& sink, const std::vector<char>* wanted) {
  const LazDescription d = parse_laszip_record(path, laszip, h);
  const std::vector<Chunk> chunks = file_chunks(path, in, h, d);
  if (wanted && wanted->size() != chunks.size())
    fail(Status::Internal, path, "asked for " + std::to_string(wanted->size()) + " parts of a file of " + std::to_string(chunks.size()) + " chunks");
  std::vector<std::size_t> todo;  // the chunks to decode, in file order; the others are neither read nor decoded
  for (std::size_t i = 0; i < chunks.size(); ++i)
    if (!wanted || (*wanted)[i]) todo.push_back(i);
  const bool layered = d.compressor == 3;
  const ThreadLimit limit(resolve_thread_count(0));
  // Batches of chunks: read in order, decoded in parallel, handed on in order. Memory: one batch's
  // compressed and decoded bytes besides the cloud.
  const std::size_t batch = std::max<std::size_t>(4, 2 * static_cast<std::size_t>(tbb::this_task_arena::max_concurrency()));
  for (std::size_t first = 0; first < todo.size(); first += batch) {
    const std::size_t last = std::min(todo.size(), first + batch);
    // Consecutive chunks are read at once: bytes[head[k]] holds chunk todo[k]'s, from chunks[todo[head[k]]].begin.
    std::vector<std::vector<unsigned char>> bytes(last - first);
    std::vector<std::size_t> head(last - first);
    for (std::size_t k = first; k < last;) {
      std::size_t m = k;
      while (m + 1 < last && todo[m + 1] == todo[m] + 1) ++m;
      const std::uint64_t from = chunks[todo[k]].begin, to = chunks[todo[m]].end;
      if (to > h.file_size || to < from) bad(path, "LAZ file is truncated: its point data ends at byte " + std::to_string(to));
      bytes[k - first] = read_bytes(path, in, from, to - from);
      for (std::size_t j = k; j <= m; ++j) head[j - first] = k - first;
      k = m + 1;
    }
    std::vector<std::vector<unsigned char>> records(last - first);
    std::vector<std::string> errors(last - first);
    tbb::parallel_for(std::size_t{first}, last, [&](std::size_t k) {
      const std::size_t at = head[k - first];
      const Chunk& c = chunks[todo[k]];
      const std::uint64_t from = chunks[todo[first + at]].begin;
      const unsigned char* b = bytes[at].data() + (c.begin - from);
      const unsigned char* e = bytes[at].data() + (c.end - from);
      errors[k - first] = layered ? decode_layered_chunk(d, h.record_length, b, e, c.points, records[k - first])
                                  : decode_pointwise_chunk(d, h.record_length, b, e, c.points, records[k - first]);
    });
    for (std::size_t k = first; k < last; ++k) {  // the first bad chunk in file order, whatever the threads did
      const std::size_t i = todo[k];
      if (!errors[k - first].empty())
        bad(path, "LAZ chunk " + std::to_string(i) + " of " + std::to_string(chunks.size()) + " is bad: " + errors[k - first]);
      sink(chunks[i].first, records[k - first].data(), chunks[i].points);
    }
  }
}

}  // namespace hsr::io_detail
