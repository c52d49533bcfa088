// PLY reader (ascii, binary little/big endian; any scalar types; lists; extra elements skipped) and writer.
#include "io/io_internal.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <memory>
#include <optional>

namespace hsr::io_detail {
namespace {

enum class Scalar { I8, U8, I16, U16, I32, U32, F32, F64 };

bool scalar_from_name(std::string_view name, Scalar& s) {
  static const std::pair<std::string_view, Scalar> table[] = {
      {"char", Scalar::I8},    {"int8", Scalar::I8},     {"uchar", Scalar::U8},    {"uint8", Scalar::U8},
      {"short", Scalar::I16},  {"int16", Scalar::I16},   {"ushort", Scalar::U16},  {"uint16", Scalar::U16},
      {"int", Scalar::I32},    {"int32", Scalar::I32},   {"uint", Scalar::U32},    {"uint32", Scalar::U32},
      {"float", Scalar::F32},  {"float32", Scalar::F32}, {"double", Scalar::F64},  {"float64", Scalar::F64}};
  for (const auto& [n, t] : table)
    if (n == name) { s = t; return true; }
  return false;
}

std::size_t scalar_size(Scalar s) {
  switch (s) {
    case Scalar::I8: case Scalar::U8: return 1;
    case Scalar::I16: case Scalar::U16: return 2;
    case Scalar::I32: case Scalar::U32: case Scalar::F32: return 4;
    case Scalar::F64: return 8;
  }
  return 0;
}

struct Property {
  std::string name;
  Scalar type = Scalar::F32;        ///< item type for lists
  bool is_list = false;
  Scalar count_type = Scalar::U8;   ///< lists only
};

struct Element {
  std::string name;
  std::uint64_t count = 0;
  std::vector<Property> properties;
};

enum class Encoding { Ascii, BinaryLittle, BinaryBig };

std::vector<std::string_view> split_words(std::string_view line) {
  std::vector<std::string_view> words;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
    std::size_t j = i;
    while (j < line.size() && line[j] != ' ' && line[j] != '\t') ++j;
    if (j > i) words.push_back(line.substr(i, j - i));
    i = j;
  }
  return words;
}

/// Reads values of the body, ascii or binary, with bounds checks that name the file. An ascii body is
/// in memory; a binary one is read from the file through a window refilled as the reader advances, so the
/// file is never held whole (a 10 M-point file costs its points, not its size on top).
class BodyReader {
 public:
  /// In memory (ascii; tests).
  BodyReader(const std::string& path, std::string_view body, Encoding enc) : path_(path), body_(body), enc_(enc) {}
  /// Binary, streamed: `first` holds the bytes already read after the header, `file` the rest (`left` bytes).
  BodyReader(const std::string& path, std::string first, std::FILE* file, std::uint64_t left, Encoding enc)
      : path_(path), window_(std::move(first)), body_(window_), enc_(enc), file_(file), file_left_(left) {}

  double read(Scalar type) {
    if (enc_ == Encoding::Ascii) return read_ascii();
    return decode(bytes(scalar_size(type)), type);
  }

  /// The next `n` bytes of a binary body (valid until the next read), or a "truncated" error.
  const unsigned char* bytes(std::size_t n) {
    if (pos_ + n > body_.size() && !refill(n))
      fail(Status::BadFormat, path_, "truncated binary PLY (data ends before the declared element counts)");
    const auto* p = reinterpret_cast<const unsigned char*>(body_.data() + pos_);
    pos_ += n;
    return p;
  }

  double decode(const unsigned char* p, Scalar type) const {
    const bool le = enc_ == Encoding::BinaryLittle;
    switch (type) {
      case Scalar::I8: return static_cast<double>(static_cast<std::int8_t>(*p));
      case Scalar::U8: return static_cast<double>(*p);
      case Scalar::I16: return load_scalar<std::int16_t>(p, le);
      case Scalar::U16: return load_scalar<std::uint16_t>(p, le);
      case Scalar::I32: return load_scalar<std::int32_t>(p, le);
      case Scalar::U32: return load_scalar<std::uint32_t>(p, le);
      case Scalar::F32: return load_scalar<float>(p, le);
      case Scalar::F64: return load_scalar<double>(p, le);
    }
    return 0.0;
  }

  /// A list length or index: must be a non-negative integer.
  std::uint64_t read_count(Scalar type, const char* what) {
    const double v = read(type);
    if (!(v >= 0) || v != std::floor(v) || v > 4294967295.0)
      fail(Status::BadFormat, path_, std::string("invalid ") + what + " in PLY data");
    return static_cast<std::uint64_t>(v);
  }

  /// Bytes not read yet: an upper bound on the values left (every value takes at least one byte).
  std::uint64_t remaining() const { return body_.size() - pos_ + file_left_; }

  bool binary() const { return enc_ != Encoding::Ascii; }

  /// True if only whitespace (ascii) or nothing (binary) is left.
  bool at_end() {
    if (enc_ == Encoding::Ascii) {
      skip_space();
      return pos_ >= body_.size();
    }
    return remaining() == 0;
  }

 private:
  /// Keeps the unread bytes and reads at least `n` more into the window (1 MB at a time or more).
  bool refill(std::size_t n) {
    if (!file_ || remaining() < n) return false;
    window_.erase(0, pos_);
    pos_ = 0;
    const std::size_t want = static_cast<std::size_t>(std::min<std::uint64_t>(file_left_, std::max<std::size_t>(n, 1 << 20)));
    const std::size_t have = window_.size();
    window_.resize(have + want);
    const std::size_t got = std::fread(window_.data() + have, 1, want, file_);
    window_.resize(have + got);
    file_left_ -= got;
    if (got != want) file_left_ = 0;  // the file shrank under us: what is there is all there is
    body_ = window_;
    return pos_ + n <= body_.size();
  }
  void skip_space() {
    while (pos_ < body_.size() && std::isspace(static_cast<unsigned char>(body_[pos_]))) ++pos_;
  }
  double read_ascii() {
    skip_space();
    if (pos_ >= body_.size())
      fail(Status::BadFormat, path_, "PLY data ends before the declared element counts (count does not match the data)");
    std::size_t j = pos_;
    while (j < body_.size() && !std::isspace(static_cast<unsigned char>(body_[j]))) ++j;
    std::string_view tok = body_.substr(pos_, j - pos_);
    pos_ = j;
    double v = 0;
    if (!parse_double(tok, v)) fail(Status::BadFormat, path_, "not a number in PLY data: '" + std::string(tok) + "'");
    return v;
  }

  const std::string& path_;
  std::string window_;
  std::string_view body_;
  Encoding enc_;
  std::size_t pos_ = 0;
  std::FILE* file_ = nullptr;
  std::uint64_t file_left_ = 0;
};

/// A file handle closed on scope exit.
struct FileCloser {
  void operator()(std::FILE* f) const { if (f) std::fclose(f); }
};
using FilePtr = std::unique_ptr<std::FILE, FileCloser>;

/// The vertex element: x y z and, when all three are there, nx ny nz. Records of fixed size (no list
/// property) are decoded straight from the bytes, slot by slot; others value by value.
void read_vertices(const std::string& path, const Element& e, BodyReader& body, RawGeometry& raw) {
  static const char* wanted[6] = {"x", "y", "z", "nx", "ny", "nz"};
  std::vector<int> slot(e.properties.size(), -1);
  std::array<bool, 6> found{};
  bool fixed = body.binary();
  std::size_t record = 0;
  std::array<std::size_t, 6> offset{};
  std::array<Scalar, 6> type{};
  for (std::size_t i = 0; i < e.properties.size(); ++i) {
    const Property& p = e.properties[i];
    if (p.is_list) { fixed = false; continue; }
    for (int k = 0; k < 6; ++k)
      if (p.name == wanted[k] && !found[k]) {
        slot[i] = k;
        found[k] = true;
        offset[k] = record;
        type[k] = p.type;
      }
    record += scalar_size(p.type);
  }
  if (!found[0] || !found[1] || !found[2]) fail(Status::BadFormat, path, "PLY vertex element lacks x, y or z");
  const bool normals = found[3] && found[4] && found[5];
  // The header's count is not trusted for memory: at most one vertex per record (ascii: per byte) of data
  // left (fuzz/fuzz_ply).
  const std::uint64_t cap = std::min<std::uint64_t>(e.count, body.remaining() / std::max<std::size_t>(1, fixed ? record : 1));
  raw.points.reserve(cap);
  if (normals) raw.normals.reserve(cap);
  if (fixed && record > 0) {
    const int wanted_slots = normals ? 6 : 3;
    for (std::uint64_t r = 0; r < e.count; ++r) {
      const unsigned char* rec = body.bytes(record);
      double v[6];
      for (int k = 0; k < wanted_slots; ++k) v[k] = body.decode(rec + offset[k], type[k]);
      raw.points.emplace_back(v[0], v[1], v[2]);
      if (normals) raw.normals.emplace_back(v[3], v[4], v[5]);
    }
    return;
  }
  std::array<double, 6> v{};
  for (std::uint64_t r = 0; r < e.count; ++r) {
    for (std::size_t i = 0; i < e.properties.size(); ++i) {
      const Property& p = e.properties[i];
      if (p.is_list) {
        const std::uint64_t n = body.read_count(p.count_type, "list length");
        for (std::uint64_t k = 0; k < n; ++k) body.read(p.type);
      } else {
        const double x = body.read(p.type);
        if (slot[i] >= 0) v[slot[i]] = x;
      }
    }
    raw.points.emplace_back(v[0], v[1], v[2]);
    if (normals) raw.normals.emplace_back(v[3], v[4], v[5]);
  }
}

}  // namespace

RawGeometry read_ply(const std::string& path) {
  // The header, read a block at a time up to its end_header line.
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) fail(Status::FileNotFound, path, "file not found");
  if (!std::filesystem::is_regular_file(path, ec)) fail(Status::FileNotFound, path, "not a regular file");
  const std::uint64_t file_size = std::filesystem::file_size(path, ec);
  if (ec) fail(Status::FileNotFound, path, "cannot read file size: " + ec.message());
  FilePtr file(std::fopen(path.c_str(), "rb"));
  if (!file) fail(Status::FileNotFound, path, "cannot open file for reading");
  std::string head;
  std::uint64_t file_left = file_size;
  std::size_t header_end = std::string::npos, scanned = 0;
  auto read_more = [&](std::size_t n) {
    const std::size_t want = static_cast<std::size_t>(std::min<std::uint64_t>(n, file_left));
    const std::size_t have = head.size();
    head.resize(have + want);
    const std::size_t got = std::fread(head.data() + have, 1, want, file.get());
    head.resize(have + got);
    file_left = got == want ? file_left - got : 0;
    return got > 0;
  };
  while (header_end == std::string::npos) {
    if (scanned >= head.size() && !read_more(1 << 16)) {  // nothing more to read (e.g. an empty file)
      header_end = head.size();
      break;
    }
    // Complete lines from `scanned` on; the header ends after the line whose first word is end_header.
    std::size_t nl;
    while (header_end == std::string::npos && (nl = head.find('\n', scanned)) != std::string::npos) {
      const auto w = split_words(std::string_view(head).substr(scanned, nl - scanned));
      if (!w.empty() && (w[0] == "end_header" || w[0] == "end_header\r")) header_end = nl + 1;
      scanned = nl + 1;
    }
    if (header_end == std::string::npos && file_left == 0) {  // a last line without '\n'
      header_end = head.size();
      break;
    }
  }
  std::string_view rest(head.data(), header_end);
  auto next_line = [&](std::string_view& line) -> bool {
    if (rest.empty()) return false;
    std::size_t nl = rest.find('\n');
    if (nl == std::string_view::npos) { line = rest; rest = {}; }
    else { line = rest.substr(0, nl); rest.remove_prefix(nl + 1); }
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    return true;
  };

  std::string_view line;
  if (!next_line(line) || line != "ply") fail(Status::BadFormat, path, "bad PLY header: first line is not 'ply'");
  Encoding enc = Encoding::Ascii;
  bool have_format = false, have_end = false;
  std::vector<Element> elements;
  while (next_line(line)) {
    auto w = split_words(line);
    if (w.empty()) continue;
    if (w[0] == "comment" || w[0] == "obj_info") continue;
    if (w[0] == "end_header") { have_end = true; break; }
    if (w[0] == "format") {
      if (w.size() < 2) fail(Status::BadFormat, path, "bad PLY header: incomplete format line");
      if (w[1] == "ascii") enc = Encoding::Ascii;
      else if (w[1] == "binary_little_endian") enc = Encoding::BinaryLittle;
      else if (w[1] == "binary_big_endian") enc = Encoding::BinaryBig;
      else fail(Status::BadFormat, path, "bad PLY header: unknown format '" + std::string(w[1]) + "'");
      have_format = true;
    } else if (w[0] == "element") {
      if (w.size() < 3) fail(Status::BadFormat, path, "bad PLY header: incomplete element line");
      Element e;
      e.name = std::string(w[1]);
      double c = 0;
      if (!parse_double(w[2], c) || !(c >= 0) || c != std::floor(c) || c > 1e15)
        fail(Status::BadFormat, path, "bad PLY header: invalid count for element '" + e.name + "'");
      e.count = static_cast<std::uint64_t>(c);
      elements.push_back(std::move(e));
    } else if (w[0] == "property") {
      if (elements.empty()) fail(Status::BadFormat, path, "bad PLY header: property before any element");
      Property p;
      bool ok;
      if (w.size() >= 2 && w[1] == "list") {
        ok = w.size() >= 5 && scalar_from_name(w[2], p.count_type) && scalar_from_name(w[3], p.type);
        p.is_list = true;
        if (ok) p.name = std::string(w[4]);
        if (ok && (p.count_type == Scalar::F32 || p.count_type == Scalar::F64)) ok = false;
      } else {
        ok = w.size() >= 3 && scalar_from_name(w[1], p.type);
        if (ok) p.name = std::string(w[2]);
      }
      if (!ok) fail(Status::BadFormat, path, "bad PLY header: cannot parse '" + std::string(line) + "'");
      elements.back().properties.push_back(std::move(p));
    } else {
      fail(Status::BadFormat, path, "bad PLY header: unexpected line '" + std::string(line) + "'");
    }
  }
  if (!have_format || !have_end) fail(Status::BadFormat, path, "bad PLY header: missing format or end_header");

  const Element* vertex_el = nullptr;
  for (const auto& e : elements)
    if (e.name == "vertex") { vertex_el = &e; break; }
  if (!vertex_el) fail(Status::BadFormat, path, "PLY file has no vertex element");

  RawGeometry raw;
  std::string ascii_body;
  std::optional<BodyReader> reader;
  if (enc == Encoding::Ascii) {  // the rest of the file in memory (tokens may span any boundary)
    ascii_body = head.substr(header_end);
    const std::size_t have = ascii_body.size();
    ascii_body.resize(have + static_cast<std::size_t>(file_left));
    ascii_body.resize(have + std::fread(ascii_body.data() + have, 1, static_cast<std::size_t>(file_left), file.get()));
    if (std::ferror(file.get())) fail(Status::FileNotFound, path, "error while reading the file");
    reader.emplace(path, ascii_body, enc);
  } else {
    reader.emplace(path, head.substr(header_end), file.get(), file_left, enc);
  }
  head.clear();
  head.shrink_to_fit();
  BodyReader& body = *reader;
  for (const auto& e : elements) {
    if (&e == vertex_el) {
      read_vertices(path, e, body, raw);
    } else {
      const bool is_face = e.name == "face";
      if (e.properties.empty()) continue;  // records of zero bytes: nothing to read (a huge count must not spin)
      if (is_face) raw.faces.reserve(std::min<std::uint64_t>(e.count, body.remaining()));
      for (std::uint64_t r = 0; r < e.count; ++r) {
        bool took_face = false;
        for (const Property& p : e.properties) {
          if (!p.is_list) { body.read(p.type); continue; }
          const std::uint64_t n = body.read_count(p.count_type, "list length");
          const bool indices = is_face && !took_face && (p.name == "vertex_indices" || p.name == "vertex_index");
          if (indices) {
            if (n > body.remaining()) fail(Status::BadFormat, path, "PLY face list longer than the data left");
            std::vector<std::uint32_t> f(n);
            for (std::uint64_t k = 0; k < n; ++k) f[k] = static_cast<std::uint32_t>(body.read_count(p.type, "vertex index"));
            raw.faces.push_back(std::move(f));
            took_face = true;
          } else {
            for (std::uint64_t k = 0; k < n; ++k) body.read(p.type);
          }
        }
      }
    }
  }
  if (!body.at_end()) fail(Status::BadFormat, path, "PLY file holds more data than its header declares (count does not match the data)");
  return raw;
}

std::string format_ply(const std::string& path, const std::vector<Vec3>& vertices, const Vec3& origin,
                       const std::vector<Vec3>& normals, const std::vector<std::array<std::uint8_t, 3>>& colors,
                       const std::vector<std::vector<std::uint32_t>>* faces, bool binary) {
  const bool with_normals = !normals.empty();
  const bool with_colors = !colors.empty();
  std::size_t max_face = 0;
  if (faces)
    for (const auto& f : *faces) max_face = std::max(max_face, f.size());
  const bool wide_count = max_face > 255;

  std::string out;
  out += "ply\nformat ";
  out += binary ? "binary_little_endian 1.0\n" : "ascii 1.0\n";
  out += "comment written by hsr\n";
  out += "element vertex " + std::to_string(vertices.size()) + "\n";
  out += "property double x\nproperty double y\nproperty double z\n";
  if (with_normals) out += "property double nx\nproperty double ny\nproperty double nz\n";
  if (with_colors) out += "property uchar red\nproperty uchar green\nproperty uchar blue\n";
  if (faces) {
    out += "element face " + std::to_string(faces->size()) + "\n";
    out += wide_count ? "property list uint int vertex_indices\n" : "property list uchar int vertex_indices\n";
  }
  out += "end_header\n";

  out.reserve(out.size() + vertices.size() * (binary ? 51 : 120));
  for (std::size_t i = 0; i < vertices.size(); ++i) {
    const Vec3 g = vertices[i] + origin;
    if (binary) {
      for (int k = 0; k < 3; ++k) store_scalar<double>(out, g[k], true);
      if (with_normals)
        for (int k = 0; k < 3; ++k) store_scalar<double>(out, normals[i][k], true);
      if (with_colors)
        for (int k = 0; k < 3; ++k) out.push_back(static_cast<char>(colors[i][k]));
    } else {
      for (int k = 0; k < 3; ++k) { if (k) out += ' '; append_double(out, g[k]); }
      if (with_normals)
        for (int k = 0; k < 3; ++k) { out += ' '; append_double(out, normals[i][k]); }
      if (with_colors)
        for (int k = 0; k < 3; ++k) { out += ' '; out += std::to_string(colors[i][k]); }
      out += '\n';
    }
  }
  if (faces) {
    for (std::size_t fi = 0; fi < faces->size(); ++fi) {
      const auto& f = (*faces)[fi];
      for (std::uint32_t v : f)
        if (v >= vertices.size() || v > static_cast<std::uint32_t>(std::numeric_limits<std::int32_t>::max()))
          fail(Status::BadInput, path, "cannot write: face " + std::to_string(fi) + " has vertex index " + std::to_string(v) +
                                           " >= " + std::to_string(vertices.size()) + " vertices");
      if (binary) {
        if (wide_count) store_scalar<std::uint32_t>(out, static_cast<std::uint32_t>(f.size()), true);
        else out.push_back(static_cast<char>(static_cast<std::uint8_t>(f.size())));
        for (std::uint32_t v : f) store_scalar<std::int32_t>(out, static_cast<std::int32_t>(v), true);
      } else {
        out += std::to_string(f.size());
        for (std::uint32_t v : f) { out += ' '; out += std::to_string(v); }
        out += '\n';
      }
    }
  }
  return out;
}

}  // namespace hsr::io_detail
