// E57 compressed-vector binary sections (ASTM E2807 §9): a 32-byte section header, then packets in logical
// byte order: data packets (type 1) carrying one chunk of every bytestream (one bytestream per prototype
// field), index packets (type 0) and empty packets (type 2), which are skipped. Each field's bytestream is the
// concatenation of its chunks; its values are bit-packed integers (value - minimum in the fewest bits that
// hold maximum - minimum, least significant bit first), scaled integers (the same, then * scale + offset) or
// little-endian IEEE floats of 4 or 8 bytes. Every length is checked against the section and the record
// count before anything is allocated from it.
#include "io/e57_internal.h"
#include "io/io_internal.h"

#include <bit>
#include <cstring>

namespace hsr::io_detail::e57 {

namespace {

constexpr std::size_t kSectionHeaderBytes = 32;
constexpr unsigned char kCompressedVectorSection = 1;
constexpr unsigned char kIndexPacket = 0, kDataPacket = 1, kEmptyPacket = 2;
constexpr std::size_t kDataPacketHeaderBytes = 6;

[[noreturn]] void vector_fail(const std::string& path, const Scan& scan, const std::string& what) {
  fail(Status::BadFormat, path, "E57 scan '" + scan.name + "': " + what);
}

/// Bits per value of an Integer / ScaledInteger field: enough for maximum - minimum (0 when they are equal).
unsigned field_bits(const Field& f) {
  if (f.type == FieldType::Float) return f.single ? 32 : 64;
  const std::uint64_t span = static_cast<std::uint64_t>(f.maximum) - static_cast<std::uint64_t>(f.minimum);
  return span == 0 ? 0 : static_cast<unsigned>(std::bit_width(span));
}

/// The `bits`-bit value starting at bit `bit` of `s` (least significant bit first); `s` holds it whole.
std::uint64_t unpack_bits(const std::string& s, std::uint64_t bit, unsigned bits) {
  const std::size_t byte = static_cast<std::size_t>(bit / 8);
  const unsigned shift = static_cast<unsigned>(bit % 8);
  unsigned char w[9] = {};
  std::memcpy(w, s.data() + byte, std::min<std::size_t>(9, s.size() - byte));
  std::uint64_t lo = load_scalar<std::uint64_t>(w, true) >> shift;
  if (shift + bits > 64) lo |= static_cast<std::uint64_t>(w[8]) << (64 - shift);
  return bits == 64 ? lo : lo & ((std::uint64_t{1} << bits) - 1);
}

/// Joins each field's chunks from the data packets of the section at `scan.section_physical_offset`,
/// stopping once every stream holds `need[i]` bytes.
std::vector<std::string> gather_streams(const std::string& path, const LogicalFile& file, const Scan& scan,
                                        const std::vector<std::uint64_t>& need) {
  const std::string& L = file.bytes;
  const auto* b = reinterpret_cast<const unsigned char*>(L.data());
  const std::uint64_t start = logical_offset(scan.section_physical_offset);
  if (start == UINT64_MAX || start > L.size() || L.size() - start < kSectionHeaderBytes)
    vector_fail(path, scan, "points section lies outside the file");
  if (b[start] != kCompressedVectorSection) vector_fail(path, scan, "points section is not a compressed vector");
  const std::uint64_t length = load_scalar<std::uint64_t>(b + start + 8, true);
  const std::uint64_t data = logical_offset(load_scalar<std::uint64_t>(b + start + 16, true));
  if (length > L.size() - start) vector_fail(path, scan, "points section runs past the end of the file (truncated)");
  const std::uint64_t end = start + length;
  if (data == UINT64_MAX || data < start + kSectionHeaderBytes || data > end)
    vector_fail(path, scan, "first data packet lies outside its section");
  const std::size_t n = scan.fields.size();
  std::vector<std::string> streams(n);
  const auto done = [&] {
    for (std::size_t i = 0; i < n; ++i)
      if (streams[i].size() < need[i]) return false;
    return true;
  };
  std::uint64_t at = data;
  while (!done()) {
    if (end - at < 4) vector_fail(path, scan, "its section ends before all " + std::to_string(scan.records) + " points (truncated)");
    const unsigned char type = b[at];
    const std::uint64_t packet = std::uint64_t{load_scalar<std::uint16_t>(b + at + 2, true)} + 1;
    if (packet > end - at) vector_fail(path, scan, "a packet runs past its section");
    if (type == kIndexPacket || type == kEmptyPacket) { at += packet; continue; }
    if (type != kDataPacket) vector_fail(path, scan, "unknown packet type " + std::to_string(type));
    if (packet < kDataPacketHeaderBytes) vector_fail(path, scan, "data packet shorter than its header");
    const std::size_t count = load_scalar<std::uint16_t>(b + at + 4, true);
    if (count != n)
      vector_fail(path, scan, "data packet of " + std::to_string(count) + " bytestreams for " + std::to_string(n) + " fields");
    std::uint64_t payload = at + kDataPacketHeaderBytes + 2 * std::uint64_t{count};
    if (payload > at + packet) vector_fail(path, scan, "data packet shorter than its bytestream lengths");
    for (std::size_t i = 0; i < n; ++i) {
      const std::uint64_t len = load_scalar<std::uint16_t>(b + at + kDataPacketHeaderBytes + 2 * i, true);
      if (len > at + packet - payload) vector_fail(path, scan, "a bytestream runs past its data packet");
      if (streams[i].size() < need[i]) streams[i].append(L, payload, std::min(len, need[i] - streams[i].size()));
      payload += len;
    }
    at += packet;
  }
  return streams;
}

/// The value of record `r` of field `f` from its whole bytestream `s`; false for an integer above the
/// field's maximum (a bit-packed value may hold more than maximum - minimum).
bool decode_value(const Field& f, unsigned bits, const std::string& s, std::uint64_t r, double& out) {
  if (f.type == FieldType::Float) {
    const auto* p = reinterpret_cast<const unsigned char*>(s.data());
    out = f.single ? double(load_scalar<float>(p + 4 * r, true)) : load_scalar<double>(p + 8 * r, true);
    return true;
  }
  const std::uint64_t raw = bits == 0 ? 0 : unpack_bits(s, r * bits, bits);
  if (raw > static_cast<std::uint64_t>(f.maximum) - static_cast<std::uint64_t>(f.minimum)) return false;
  const auto value = static_cast<std::int64_t>(static_cast<std::uint64_t>(f.minimum) + raw);  // two's complement
  out = f.type == FieldType::Integer ? double(value) : double(value) * f.scale + f.offset;
  return true;
}

}  // namespace

std::vector<std::vector<double>> read_columns(const std::string& path, const LogicalFile& file, const Scan& scan,
                                              const std::vector<std::size_t>& wanted) {
  const std::size_t n = scan.fields.size();
  std::vector<unsigned> bits(n);
  std::vector<std::uint64_t> need(n);
  std::uint64_t bits_per_record = 0;
  for (std::size_t i = 0; i < n; ++i) {
    bits[i] = field_bits(scan.fields[i]);
    need[i] = (scan.records * bits[i] + 7) / 8;  // records <= E57Limits::max_points: no overflow
    bits_per_record += bits[i];
  }
  // A record of zero bits would let a tiny file claim any number of points: every one the same.
  if (bits_per_record == 0 && scan.records > 0) vector_fail(path, scan, "every field is constant (no point data)");
  std::uint64_t total = 0;
  for (std::uint64_t x : need) total += x;
  if (total > file.bytes.size())
    vector_fail(path, scan, std::to_string(scan.records) + " points need " + std::to_string(total) +
                                " bytes, more than the file holds (truncated or corrupt)");
  const std::vector<std::string> streams = gather_streams(path, file, scan, need);
  std::vector<std::vector<double>> columns;
  for (std::size_t w : wanted) {
    const Field& f = scan.fields[w];
    std::vector<double> col(scan.records);
    for (std::uint64_t r = 0; r < scan.records; ++r)
      if (!decode_value(f, bits[w], streams[w], r, col[r]))
        vector_fail(path, scan, "point " + std::to_string(r) + ": " + f.name + " above its maximum");
    columns.push_back(std::move(col));
  }
  return columns;
}

}  // namespace hsr::io_detail::e57
