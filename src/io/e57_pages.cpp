// E57 physical file (ASTM E2807 §8.4.1-8.4.2): 1024-byte pages, each ending in the CRC-32C of its first
// 1020 bytes (stored most significant byte first, as libE57Format writes it); the 48-byte file header at
// offset 0. Every page's checksum is verified and the payloads are joined into the file's logical bytes, in
// the same buffer (the file is read once).
#include "io/e57_internal.h"
#include "io/io_internal.h"

#include <cstring>

namespace hsr::io_detail::e57 {

namespace {

/// The reflected CRC-32C table (polynomial 0x1EDC6F41, reflected 0x82F63B78).
std::array<std::uint32_t, 256> make_crc32c_table() {
  std::array<std::uint32_t, 256> t{};
  for (std::uint32_t i = 0; i < 256; ++i) {
    std::uint32_t c = i;
    for (int k = 0; k < 8; ++k) c = (c & 1) ? (c >> 1) ^ 0x82F63B78u : c >> 1;
    t[i] = c;
  }
  return t;
}

}  // namespace

std::uint32_t crc32c(const unsigned char* data, std::size_t n) {
  static const std::array<std::uint32_t, 256> table = make_crc32c_table();
  std::uint32_t c = 0xFFFFFFFFu;
  for (std::size_t i = 0; i < n; ++i) c = table[(c ^ data[i]) & 0xFF] ^ (c >> 8);
  return c ^ 0xFFFFFFFFu;
}

std::uint64_t logical_offset(std::uint64_t physical) {
  const std::uint64_t in_page = physical % kPageBytes;
  if (in_page >= kPagePayload) return UINT64_MAX;
  return physical / kPageBytes * kPagePayload + in_page;
}

std::uint64_t physical_offset(std::uint64_t logical) {
  return logical / kPagePayload * kPageBytes + logical % kPagePayload;
}

LogicalFile read_pages(const std::string& path, std::string file) {
  const auto* b = reinterpret_cast<const unsigned char*>(file.data());
  if (file.size() < kFileHeaderBytes || std::memcmp(b, "ASTM-E57", 8) != 0)
    fail(Status::BadFormat, path, "not an E57 file (no 'ASTM-E57' signature)");
  LogicalFile out;
  FileHeader& h = out.header;
  h.major = load_scalar<std::uint32_t>(b + 8, true);
  h.minor = load_scalar<std::uint32_t>(b + 12, true);
  h.physical_length = load_scalar<std::uint64_t>(b + 16, true);
  h.xml_physical_offset = load_scalar<std::uint64_t>(b + 24, true);
  h.xml_logical_length = load_scalar<std::uint64_t>(b + 32, true);
  h.page_size = load_scalar<std::uint64_t>(b + 40, true);
  if (h.major != 1) fail(Status::BadFormat, path, "E57 version " + std::to_string(h.major) + " (only 1.x is known)");
  if (h.page_size != kPageBytes)
    fail(Status::BadFormat, path, "E57 page size " + std::to_string(h.page_size) + " (only 1024 is known)");
  if (h.physical_length != file.size())
    fail(Status::BadFormat, path, "E57 header says " + std::to_string(h.physical_length) + " bytes but the file has " +
                                      std::to_string(file.size()) + " (truncated or corrupt)");
  if (file.size() % kPageBytes != 0)
    fail(Status::BadFormat, path, "E57 file of " + std::to_string(file.size()) + " bytes is not whole 1024-byte pages");
  const std::size_t pages = file.size() / kPageBytes;
  for (std::size_t p = 0; p < pages; ++p) {
    const unsigned char* page = b + p * kPageBytes;
    const std::uint32_t stored = load_scalar<std::uint32_t>(page + kPagePayload, false);  // big-endian
    if (crc32c(page, kPagePayload) != stored)
      fail(Status::BadFormat, path, "E57 page " + std::to_string(p) + " fails its CRC-32C checksum (corrupt file)");
    if (p > 0) std::memmove(file.data() + p * kPagePayload, page, kPagePayload);
  }
  file.resize(pages * kPagePayload);
  out.bytes = std::move(file);
  const std::uint64_t xml_start = logical_offset(h.xml_physical_offset);
  if (xml_start == UINT64_MAX || xml_start > out.bytes.size() || h.xml_logical_length > out.bytes.size() - xml_start)
    fail(Status::BadFormat, path, "E57 XML section lies outside the file");
  return out;
}

}  // namespace hsr::io_detail::e57
