// E57 XML section (ASTM E2807 §8.4.3-8.4.9), parsed with Xerces-C (DOM, namespaces on, no validation, no
// external entities) into the scans of /data3D: each scan's pose (rotation quaternion, translation), its
// points' compressed vector (fileOffset, recordCount, the prototype's fields in bytestream order) and its
// intensity and colour limits. Only what the reader uses is read; images2D and the other nodes are ignored.
// Built into the module libhsr_xml.so (core/module.h, DECISIONS #188), entry hsr_xml_parse_e57 (e57_internal.h).
#include "io/e57_internal.h"
#include "io/io_internal.h"

#include <xercesc/dom/DOM.hpp>
#include <xercesc/framework/MemBufInputSource.hpp>
#include <xercesc/parsers/XercesDOMParser.hpp>
#include <xercesc/sax/HandlerBase.hpp>
#include <xercesc/util/PlatformUtils.hpp>
#include <xercesc/util/TransService.hpp>

#include <charconv>
#include <cmath>
#include <mutex>

namespace hsr::io_detail::e57 {

namespace {

namespace xc = xercesc;

/// Xerces is initialised once per process and never terminated (its static state stays reachable).
void ensure_xerces() {
  static std::once_flag once;
  std::call_once(once, [] { xc::XMLPlatformUtils::Initialize(); });
}

std::string utf8(const XMLCh* s) {
  if (!s) return {};
  xc::TranscodeToStr t(s, "UTF-8");
  return std::string(reinterpret_cast<const char*>(t.str()), t.length());
}

/// Throws on the first XML error, so a malformed section is one line.
struct ThrowingErrors : xc::HandlerBase {
  void error(const xc::SAXParseException& e) override { throw e; }
  void fatalError(const xc::SAXParseException& e) override { throw e; }
  void warning(const xc::SAXParseException&) override {}
};

std::string xml_name(const xc::DOMElement* e) {
  return utf8(e->getLocalName() ? e->getLocalName() : e->getTagName());
}

const xc::DOMElement* xml_child(const xc::DOMElement* parent, std::string_view name) {
  if (!parent) return nullptr;
  for (const xc::DOMElement* c = parent->getFirstElementChild(); c; c = c->getNextElementSibling())
    if (xml_name(c) == name) return c;
  return nullptr;
}

std::string xml_attr(const xc::DOMElement* e, const char* name) {
  XMLCh* n = xc::XMLString::transcode(name);
  const std::string v = utf8(e->getAttribute(n));
  xc::XMLString::release(&n);
  return v;
}

std::string trimmed(std::string s) {
  const auto blank = [](char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; };
  while (!s.empty() && blank(s.back())) s.pop_back();
  std::size_t i = 0;
  while (i < s.size() && blank(s[i])) ++i;
  return s.substr(i);
}

[[noreturn]] void xml_fail(const std::string& path, const std::string& what) {
  fail(Status::BadFormat, path, "E57 XML: " + what);
}

double number_of(const std::string& path, const std::string& text, const std::string& what) {
  double v = 0;
  if (!parse_double(trimmed(text), v) || !std::isfinite(v)) xml_fail(path, what + " is not a finite number: '" + text + "'");
  return v;
}

std::int64_t integer_of(const std::string& path, const std::string& text, const std::string& what) {
  const std::string t = trimmed(text);
  std::int64_t v = 0;
  const auto [p, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
  if (t.empty() || ec != std::errc() || p != t.data() + t.size()) xml_fail(path, what + " is not an integer: '" + text + "'");
  return v;
}

/// The value of a Float / Integer / ScaledInteger child `name` of `parent`, or `fallback` when absent.
double child_number(const std::string& path, const xc::DOMElement* parent, const char* name, double fallback) {
  const xc::DOMElement* c = xml_child(parent, name);
  if (!c) return fallback;
  const std::string text = utf8(c->getTextContent());
  return trimmed(text).empty() ? 0.0 : number_of(path, text, name);  // E2807: an empty element is 0
}

Field parse_field(const std::string& path, const xc::DOMElement* e) {
  Field f;
  f.name = xml_name(e);
  const std::string type = xml_attr(e, "type");
  const std::string min = xml_attr(e, "minimum"), max = xml_attr(e, "maximum");
  if (type == "Integer" || type == "ScaledInteger") {
    f.type = type == "Integer" ? FieldType::Integer : FieldType::ScaledInteger;
    if (!min.empty()) f.minimum = integer_of(path, min, f.name + " minimum");
    if (!max.empty()) f.maximum = integer_of(path, max, f.name + " maximum");
    if (f.minimum > f.maximum) xml_fail(path, f.name + ": minimum above maximum");
    if (f.type == FieldType::ScaledInteger) {
      const std::string scale = xml_attr(e, "scale"), offset = xml_attr(e, "offset");
      if (!scale.empty()) f.scale = number_of(path, scale, f.name + " scale");
      if (!offset.empty()) f.offset = number_of(path, offset, f.name + " offset");
      if (f.scale == 0) xml_fail(path, f.name + ": scale 0");
    }
  } else if (type == "Float") {
    f.type = FieldType::Float;
    const std::string precision = xml_attr(e, "precision");
    if (precision == "single") f.single = true;
    else if (!precision.empty() && precision != "double") xml_fail(path, f.name + ": precision '" + precision + "'");
    if (!min.empty() && !max.empty()) {
      f.float_min = number_of(path, min, f.name + " minimum");
      f.float_max = number_of(path, max, f.name + " maximum");
      f.has_float_bounds = true;
    }
  } else {
    xml_fail(path, "point field '" + f.name + "' of type '" + type + "' is not supported (Integer, ScaledInteger, Float)");
  }
  return f;
}

void parse_pose(const std::string& path, const xc::DOMElement* pose, Scan& s) {
  if (!pose) return;
  if (const xc::DOMElement* r = xml_child(pose, "rotation")) {
    s.rotation = {child_number(path, r, "w", 1), child_number(path, r, "x", 0), child_number(path, r, "y", 0),
                  child_number(path, r, "z", 0)};
  }
  if (const xc::DOMElement* t = xml_child(pose, "translation"))
    s.translation = Vec3(child_number(path, t, "x", 0), child_number(path, t, "y", 0), child_number(path, t, "z", 0));
}

/// The (minimum, maximum) of an intensityLimits / colorLimits structure, if present.
bool parse_limits(const std::string& path, const xc::DOMElement* scan, const char* node, const char* min_name,
                  const char* max_name, double& lo, double& hi) {
  const xc::DOMElement* l = xml_child(scan, node);
  if (!l || !xml_child(l, min_name) || !xml_child(l, max_name)) return false;
  lo = child_number(path, l, min_name, 0);
  hi = child_number(path, l, max_name, 0);
  return true;
}

Scan parse_scan(const std::string& path, const xc::DOMElement* e, const E57Limits& limits) {
  Scan s;
  if (const xc::DOMElement* n = xml_child(e, "name")) s.name = trimmed(utf8(n->getTextContent()));
  parse_pose(path, xml_child(e, "pose"), s);
  const xc::DOMElement* points = xml_child(e, "points");
  if (!points || xml_attr(points, "type") != "CompressedVector") xml_fail(path, "a scan without a 'points' compressed vector");
  s.section_physical_offset = static_cast<std::uint64_t>(integer_of(path, xml_attr(points, "fileOffset"), "points fileOffset"));
  const std::int64_t records = integer_of(path, xml_attr(points, "recordCount"), "points recordCount");
  if (records < 0) xml_fail(path, "negative recordCount");
  s.records = static_cast<std::uint64_t>(records);
  const xc::DOMElement* proto = xml_child(points, "prototype");
  if (!proto) xml_fail(path, "points without a prototype");
  for (const xc::DOMElement* c = proto->getFirstElementChild(); c; c = c->getNextElementSibling()) {
    if (s.fields.size() >= limits.max_fields)
      xml_fail(path, "a prototype of more than " + std::to_string(limits.max_fields) + " fields (E57Limits::max_fields)");
    s.fields.push_back(parse_field(path, c));
  }
  s.has_intensity_limits = parse_limits(path, e, "intensityLimits", "intensityMinimum", "intensityMaximum",
                                        s.intensity_min, s.intensity_max);
  s.has_color_limits = parse_limits(path, e, "colorLimits", "colorRedMinimum", "colorRedMaximum", s.color_min, s.color_max);
  return s;
}

}  // namespace

}  // namespace hsr::io_detail::e57

using namespace hsr;
using namespace hsr::io_detail::e57;

std::vector<Scan> hsr_xml_parse_e57(const std::string& path, std::string_view xml, const E57Limits& limits) {
  if (xml.size() > limits.max_xml_bytes)
    xml_fail(path, "section of " + std::to_string(xml.size()) + " bytes, over E57Limits::max_xml_bytes");
  ensure_xerces();
  std::vector<Scan> scans;
  try {
    xc::XercesDOMParser parser;
    parser.setValidationScheme(xc::XercesDOMParser::Val_Never);
    parser.setDoNamespaces(true);
    parser.setDoSchema(false);
    parser.setLoadExternalDTD(false);
    parser.setDisableDefaultEntityResolution(true);
    parser.setCreateEntityReferenceNodes(false);
    ThrowingErrors errors;
    parser.setErrorHandler(&errors);
    xc::MemBufInputSource source(reinterpret_cast<const XMLByte*>(xml.data()), xml.size(), "e57-xml");
    parser.parse(source);
    const xc::DOMDocument* doc = parser.getDocument();
    const xc::DOMElement* root = doc ? doc->getDocumentElement() : nullptr;
    if (!root || xml_name(root) != "e57Root") xml_fail(path, "no e57Root element");
    const xc::DOMElement* data3d = xml_child(root, "data3D");
    if (!data3d) xml_fail(path, "no data3D (the file holds no point cloud)");
    for (const xc::DOMElement* c = data3d->getFirstElementChild(); c; c = c->getNextElementSibling()) {
      if (scans.size() >= limits.max_scans)
        xml_fail(path, "more than " + std::to_string(limits.max_scans) + " scans (E57Limits::max_scans)");
      scans.push_back(parse_scan(path, c, limits));
    }
  } catch (const xc::SAXParseException& e) {
    xml_fail(path, "line " + std::to_string(e.getLineNumber()) + ": " + utf8(e.getMessage()));
  } catch (const xc::XMLException& e) {
    xml_fail(path, utf8(e.getMessage()));
  } catch (const xc::DOMException& e) {
    xml_fail(path, utf8(e.getMessage()));
  }
  if (scans.empty()) xml_fail(path, "data3D holds no scan");
  return scans;
}
