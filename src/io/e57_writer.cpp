// The tests' E57 writer (io/e57_writer.h): the logical bytes (file header, one compressed-vector section per
// scan, the XML last), then cut into 1024-byte pages, each closed by its CRC-32C (most significant byte first).
#include "io/e57_writer.h"

#include "core/atomic_file.h"
#include "io/e57_internal.h"
#include "io/io_internal.h"

#include <algorithm>
#include <bit>
#include <cmath>

namespace hsr {

namespace {

using io_detail::append_double;
using io_detail::store_scalar;

/// One prototype field and its whole bytestream.
struct WriterField {
  std::string xml;     ///< the prototype element
  std::string stream;  ///< the bytestream
};

std::string number_text(double v) {
  std::string s;
  append_double(s, v);
  return s;
}

/// Bit-packs `values` (each in [minimum, maximum]) least significant bit first.
WriterField packed_integers(const std::string& name, const std::vector<std::int64_t>& values, std::int64_t minimum,
                            std::int64_t maximum, double scale = 0) {
  WriterField f;
  f.xml = "<" + name + (scale > 0 ? " type=\"ScaledInteger\"" : " type=\"Integer\"") + " minimum=\"" + std::to_string(minimum) +
          "\" maximum=\"" + std::to_string(maximum) + "\"" + (scale > 0 ? " scale=\"" + number_text(scale) + "\" offset=\"0\"" : "") +
          "/>";
  const std::uint64_t span = static_cast<std::uint64_t>(maximum) - static_cast<std::uint64_t>(minimum);
  const unsigned bits = span == 0 ? 0 : static_cast<unsigned>(std::bit_width(span));
  std::uint64_t bit = 0;
  f.stream.assign((values.size() * bits + 7) / 8, '\0');
  for (std::int64_t v : values) {
    const std::uint64_t raw = static_cast<std::uint64_t>(v) - static_cast<std::uint64_t>(minimum);
    for (unsigned k = 0; k < bits; ++k, ++bit)
      if ((raw >> k) & 1) f.stream[bit / 8] = static_cast<char>(f.stream[bit / 8] | (1 << (bit % 8)));
  }
  return f;
}

WriterField doubles(const std::string& name, const std::vector<double>& values) {
  WriterField f;
  f.xml = "<" + name + " type=\"Float\" precision=\"double\"/>";
  for (double v : values) store_scalar(f.stream, v, true);
  return f;
}

WriterField singles(const std::string& name, const std::vector<float>& values) {
  WriterField f;
  f.xml = "<" + name + " type=\"Float\" precision=\"single\" minimum=\"0\" maximum=\"1\"/>";
  for (float v : values) store_scalar(f.stream, v, true);
  return f;
}

std::vector<WriterField> scan_fields(const E57WriteScan& s) {
  const std::size_t n = s.points.size();
  const auto check = [&](std::size_t size, const char* what) {
    if (size != 0 && size != n)
      throw Error(Status::BadInput, "io", std::string("E57 writer: ") + what + " must be empty or one per point");
  };
  check(s.invalid_state.size(), "invalid_state");
  check(s.row.size(), "row");
  check(s.column.size(), "column");
  check(s.intensity.size(), "intensity");
  check(s.color.size(), "color");
  std::vector<WriterField> fields;
  const char* names[3] = {"cartesianX", "cartesianY", "cartesianZ"};
  const char* spherical[3] = {"sphericalRange", "sphericalAzimuth", "sphericalElevation"};
  for (int k = 0; k < 3; ++k) {
    const std::string name = s.spherical ? spherical[k] : names[k];
    if (s.scaled_integer_scale > 0) {
      std::vector<std::int64_t> raw(n);
      for (std::size_t i = 0; i < n; ++i) raw[i] = std::llround(s.points[i][k] / s.scaled_integer_scale);
      const auto [lo, hi] = n ? std::minmax_element(raw.begin(), raw.end()) : std::minmax_element(raw.end(), raw.end());
      fields.push_back(packed_integers(name, raw, n ? *lo : 0, n ? *hi : 0, s.scaled_integer_scale));
    } else {
      std::vector<double> v(n);
      for (std::size_t i = 0; i < n; ++i) v[i] = s.points[i][k];
      fields.push_back(doubles(name, v));
    }
  }
  if (!s.invalid_state.empty())
    fields.push_back(packed_integers(s.spherical ? "sphericalInvalidState" : "cartesianInvalidState",
                                     {s.invalid_state.begin(), s.invalid_state.end()}, 0, 2));
  if (!s.row.empty()) {
    const std::int64_t rows = *std::max_element(s.row.begin(), s.row.end());
    const std::int64_t columns = s.column.empty() ? 0 : *std::max_element(s.column.begin(), s.column.end());
    fields.push_back(packed_integers("rowIndex", {s.row.begin(), s.row.end()}, 0, rows));
    fields.push_back(packed_integers("columnIndex", {s.column.begin(), s.column.end()}, 0, columns));
  }
  if (!s.intensity.empty()) fields.push_back(singles("intensity", s.intensity));
  if (!s.color.empty()) {
    const char* channels[3] = {"colorRed", "colorGreen", "colorBlue"};
    for (int c = 0; c < 3; ++c) {
      std::vector<std::int64_t> v(n);
      for (std::size_t i = 0; i < n; ++i) v[i] = s.color[i][static_cast<std::size_t>(c)];
      fields.push_back(packed_integers(channels[c], v, 0, 255));
    }
  }
  return fields;
}

/// Appends one compressed-vector section (header, data packets) at the end of `logical`.
void append_section(std::string& logical, const std::vector<WriterField>& fields, const E57WriteOptions& options) {
  namespace e57 = io_detail::e57;
  while (logical.size() % 4) logical.push_back('\0');
  const std::size_t start = logical.size();
  logical.append(32, '\0');
  logical[start] = 1;  // compressed vector
  const std::size_t n = fields.size();
  const std::size_t max_packet = 65536;  // the packet length is a 16-bit count minus one
  const std::size_t chunk = std::max<std::size_t>(1, std::min(options.max_chunk_bytes, (max_packet - 8 - 2 * n) / std::max<std::size_t>(1, n)));
  std::vector<std::size_t> done(n, 0);
  const auto remaining = [&] {
    for (std::size_t i = 0; i < n; ++i)
      if (done[i] < fields[i].stream.size()) return true;
    return false;
  };
  do {  // at least one packet, even for a scan of no points
    std::string packet;
    packet.push_back(1);  // data packet
    packet.push_back(0);
    packet.append(2, '\0');  // length - 1, below
    store_scalar(packet, static_cast<std::uint16_t>(n), true);
    std::vector<std::size_t> take(n);
    for (std::size_t i = 0; i < n; ++i) {
      take[i] = std::min(chunk, fields[i].stream.size() - done[i]);
      store_scalar(packet, static_cast<std::uint16_t>(take[i]), true);
    }
    for (std::size_t i = 0; i < n; ++i) {
      packet.append(fields[i].stream, done[i], take[i]);
      done[i] += take[i];
    }
    while (packet.size() % 4) packet.push_back('\0');
    const auto length_minus_1 = static_cast<std::uint16_t>(packet.size() - 1);
    std::string len;
    store_scalar(len, length_minus_1, true);
    packet.replace(2, 2, len);
    logical += packet;
  } while (remaining());
  std::string head;
  store_scalar(head, static_cast<std::uint64_t>(logical.size() - start), true);
  store_scalar(head, e57::physical_offset(start + 32), true);
  store_scalar(head, std::uint64_t{0}, true);  // no index packet
  logical.replace(start + 8, 24, head);
}

std::string pose_xml(const E57WriteScan& s) {
  std::string x = "<pose type=\"Structure\"><rotation type=\"Structure\">";
  const char* q[4] = {"w", "x", "y", "z"};
  for (int k = 0; k < 4; ++k) x += std::string("<") + q[k] + " type=\"Float\">" + number_text(s.rotation[std::size_t(k)]) + "</" + q[k] + ">";
  x += "</rotation><translation type=\"Structure\">";
  for (int k = 0; k < 3; ++k) x += std::string("<") + q[k + 1] + " type=\"Float\">" + number_text(s.translation[k]) + "</" + q[k + 1] + ">";
  return x + "</translation></pose>";
}

}  // namespace

std::string e57_file_bytes(const std::vector<E57WriteScan>& scans, const E57WriteOptions& options) {
  namespace e57 = io_detail::e57;
  std::string logical(e57::kFileHeaderBytes, '\0');
  std::string data3d;
  for (std::size_t k = 0; k < scans.size(); ++k) {
    const E57WriteScan& s = scans[k];
    const std::vector<WriterField> fields = scan_fields(s);
    while (logical.size() % 4) logical.push_back('\0');
    const std::uint64_t section = e57::physical_offset(logical.size());
    append_section(logical, fields, options);
    data3d += "<vectorChild type=\"Structure\"><guid type=\"String\"><![CDATA[hsr-scan-" + std::to_string(k) +
              "]]></guid><name type=\"String\"><![CDATA[" + s.name + "]]></name>" + pose_xml(s);
    if (!s.intensity.empty())
      data3d += "<intensityLimits type=\"Structure\"><intensityMinimum type=\"Float\">0</intensityMinimum>"
                "<intensityMaximum type=\"Float\">1</intensityMaximum></intensityLimits>";
    if (!s.color.empty()) {
      data3d += "<colorLimits type=\"Structure\">";
      for (const char* c : {"Red", "Green", "Blue"})
        data3d += std::string("<color") + c + "Minimum type=\"Integer\">0</color" + c + "Minimum><color" + c +
                  "Maximum type=\"Integer\">255</color" + c + "Maximum>";
      data3d += "</colorLimits>";
    }
    data3d += "<points type=\"CompressedVector\" fileOffset=\"" + std::to_string(section) + "\" recordCount=\"" +
              std::to_string(s.points.size()) + "\"><prototype type=\"Structure\">";
    for (const WriterField& f : fields) data3d += f.xml;
    data3d += "</prototype><codecs type=\"Vector\" allowHeterogeneousChildren=\"1\"/></points></vectorChild>";
  }
  const std::string xml =
      "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<e57Root type=\"Structure\" "
      "xmlns=\"http://www.astm.org/COMMIT/E57/2010-e57-v1.0\"><formatName type=\"String\"><![CDATA[ASTM E57 3D Imaging "
      "Data File]]></formatName><guid type=\"String\"><![CDATA[hsr-file]]></guid><versionMajor type=\"Integer\">1"
      "</versionMajor><versionMinor type=\"Integer\">0</versionMinor><data3D type=\"Vector\" "
      "allowHeterogeneousChildren=\"1\">" + data3d + "</data3D><images2D type=\"Vector\" allowHeterogeneousChildren=\"1\"/></e57Root>\n";
  while (logical.size() % 4) logical.push_back('\0');
  const std::size_t xml_start = logical.size();
  logical += xml;
  const std::size_t pages = (logical.size() + e57::kPagePayload - 1) / e57::kPagePayload;
  std::string head = "ASTM-E57";
  store_scalar(head, std::uint32_t{1}, true);
  store_scalar(head, std::uint32_t{0}, true);
  store_scalar(head, static_cast<std::uint64_t>(pages * e57::kPageBytes), true);
  store_scalar(head, e57::physical_offset(xml_start), true);
  store_scalar(head, static_cast<std::uint64_t>(xml.size()), true);
  store_scalar(head, e57::kPageBytes, true);
  logical.replace(0, head.size(), head);
  logical.resize(pages * e57::kPagePayload, '\0');
  std::string file;
  file.reserve(pages * e57::kPageBytes);
  for (std::size_t p = 0; p < pages; ++p) {
    file.append(logical, p * e57::kPagePayload, e57::kPagePayload);
    const std::uint32_t crc = e57::crc32c(reinterpret_cast<const unsigned char*>(file.data()) + p * e57::kPageBytes, e57::kPagePayload);
    store_scalar(file, crc, false);  // most significant byte first
  }
  return file;
}

void write_e57(const std::string& path, const std::vector<E57WriteScan>& scans, const E57WriteOptions& options) {
  const std::string bytes = e57_file_bytes(scans, options);
  AtomicFile f(path, "io");
  f.stream().write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  f.commit();
}

}  // namespace hsr
