// Tests of stage 0 (io): round trips of every reader on every writer's output, hand-made PLY (big-endian,
// mixed types, lists, extra elements), OBJ/OFF variants, mesh sampling, LAS 1.2/1.4, every error case, and
// the shared real scans against their MANIFEST.
#include "io/io.h"

#include "core/error.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <random>
#include <sstream>

namespace fs = std::filesystem;
using namespace hsr;

namespace {

std::string tmp_path(const std::string& name) {
  fs::create_directories(HSR_TEST_TMP_DIR);
  return std::string(HSR_TEST_TMP_DIR) + "/" + name;
}

void write_file(const std::string& path, const std::string& content) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << content;
}

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// Runs f, expects hsr::Error with `status`, stage "io" and a message naming `path`.
void expect_error(const std::function<void()>& f, Status status, const std::string& path) {
  try {
    f();
    ADD_FAILURE() << "no error thrown for " << path;
  } catch (const Error& e) {
    EXPECT_EQ(e.status(), status) << e.one_line();
    EXPECT_EQ(e.stage(), "io");
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << "message must be one line";
  }
}

PointCloud random_cloud(std::size_t n, bool normals, const Vec3& origin, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-50.0, 50.0);
  PointCloud c;
  c.origin = origin;
  for (std::size_t i = 0; i < n; ++i) {
    c.points.emplace_back(u(rng), u(rng), u(rng));
    if (normals) c.normals.push_back(Vec3(u(rng), u(rng), u(rng)).normalized());
  }
  return c;
}

std::vector<Vec3> global(const PointCloud& c) {
  std::vector<Vec3> g;
  for (const auto& p : c.points) g.push_back(p + c.origin);
  return g;
}

// A unit-free cube [-1,1]^3 as 6 outward-oriented quads.
PolygonMesh cube_mesh(const Vec3& origin) {
  PolygonMesh m;
  m.origin = origin;
  for (int i = 0; i < 8; ++i) m.vertices.emplace_back(i & 1 ? 1 : -1, i & 2 ? 1 : -1, i & 4 ? 1 : -1);
  m.faces = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  return m;
}

// ---- tiny binary writers used to build fixtures ----
template <class T>
void put(std::string& s, T v, bool little) {
  unsigned char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));
  if (!little) std::reverse(b, b + sizeof(T));  // the test machine is little-endian (checked below)
  s.append(reinterpret_cast<char*>(b), sizeof(T));
}

}  // namespace

TEST(IoHost, LittleEndian) {
  const std::uint16_t one = 1;
  unsigned char b;
  std::memcpy(&b, &one, 1);
  ASSERT_EQ(b, 1) << "the fixture writers assume a little-endian host";
}

TEST(IoFileExtension, LowerCaseWithoutDot) {
  EXPECT_EQ(file_extension("a/b/scan.PLY"), "ply");
  EXPECT_EQ(file_extension("x.tar.gz"), "gz");
  EXPECT_EQ(file_extension("dir.d/noext"), "");
  EXPECT_EQ(file_extension(".hidden"), "");
  EXPECT_EQ(file_extension("cloud.XyZn"), "xyzn");
}

TEST(IoRoundTrip, PointWritersAndReadersExact) {
  for (bool normals : {false, true}) {
    for (const Vec3& origin : {Vec3(0, 0, 0), Vec3(512000, 5400000, 100)}) {
      const PointCloud c = random_cloud(500, normals, origin, 7);
      const auto expected = global(c);
      struct Case { std::string ext; FileEncoding enc; };
      std::vector<Case> cases = {{"ply", FileEncoding::Binary}, {"ply", FileEncoding::Ascii}, {"xyz", FileEncoding::Ascii}};
      if (normals) cases.push_back({"xyzn", FileEncoding::Ascii});
      for (const auto& cs : cases) {
        const std::string path = tmp_path("rt_" + std::to_string(normals) + "_" + std::to_string(origin.x() > 0) + "_" +
                                          std::to_string(cs.enc == FileEncoding::Binary) + "." + cs.ext);
        write_points(path, c, cs.enc);
        const PointCloud r = read_points(path);
        SCOPED_TRACE(path);
        ASSERT_EQ(r.size(), c.size());
        EXPECT_EQ(r.source, path);
        EXPECT_EQ(r.origin.x() != 0, origin.x() != 0) << "large coordinates must be shifted, small ones not";
        // Origins are integers, so the shift is exact: global coordinates come back bit for bit.
        for (std::size_t i = 0; i < c.size(); ++i) {
          ASSERT_EQ(r.points[i] + r.origin, expected[i]) << i;
          EXPECT_EQ(r.origin, r.origin.array().round().matrix());
        }
        const bool expect_normals = normals && cs.ext != "xyz";
        ASSERT_EQ(r.has_normals(), expect_normals);
        if (expect_normals)
          for (std::size_t i = 0; i < c.size(); ++i) ASSERT_EQ(r.normals[i], c.normals[i]) << i;
      }
    }
  }
}

TEST(IoRoundTrip, PlyColorsAreWrittenAndIgnoredOnRead) {
  const PointCloud c = random_cloud(20, true, Vec3::Zero(), 3);
  std::vector<std::array<std::uint8_t, 3>> colors;
  for (std::size_t i = 0; i < c.size(); ++i) colors.push_back({std::uint8_t(i), std::uint8_t(2 * i), 255});
  for (auto enc : {FileEncoding::Ascii, FileEncoding::Binary}) {
    const std::string path = tmp_path(std::string("colors_") + (enc == FileEncoding::Ascii ? "a" : "b") + ".ply");
    write_points(path, c, enc, colors);
    const std::string text = slurp(path);
    EXPECT_NE(text.find("property uchar red"), std::string::npos);
    if (enc == FileEncoding::Binary) {
      // header + 20 * (6 doubles + 3 bytes)
      const std::size_t header = text.find("end_header\n") + 11;
      EXPECT_EQ(text.size() - header, 20u * (6 * 8 + 3));
      EXPECT_EQ(static_cast<unsigned char>(text[header + 5 * 51 + 48 + 1]), 10u);  // green of point 5
    }
    const PointCloud r = read_points(path);
    ASSERT_EQ(r.size(), 20u);
    for (std::size_t i = 0; i < c.size(); ++i) EXPECT_EQ(r.points[i], c.points[i]);
  }
  expect_error([&] { write_points(tmp_path("badcolors.ply"), c, FileEncoding::Binary, {{1, 2, 3}}); }, Status::BadInput,
               tmp_path("badcolors.ply"));
}

/// Writes a PLY by hand: mixed scalar types, properties out of order, a list inside the vertex element,
/// extra properties, a face element and an extra element with lists before and after the vertices.
std::string handmade_ply(const std::string& format, const std::vector<std::array<double, 6>>& v, bool little) {
  std::string h = "ply\nformat " + format + " 1.0\ncomment hand made\nobj_info test\n";
  h += "element camera 1\nproperty list uchar float matrix\nproperty int8 id\n";
  h += "element vertex " + std::to_string(v.size()) + "\n";
  h += "property uint16 quality\nproperty float64 z\nproperty list ushort int16 junk\nproperty float32 x\n"
       "property float nx\nproperty double y\nproperty char flag\nproperty float ny\nproperty float32 nz\nproperty uint8 red\n";
  h += "element face 2\nproperty uchar flags\nproperty list uchar uint vertex_indices\n";
  h += "element edge 1\nproperty list int int pair\nend_header\n";
  std::string b;
  const bool ascii = format == "ascii";
  auto num = [&](auto x) { b += std::to_string(x) + " "; };
  auto dbl = [&](double x) { std::ostringstream s; s.precision(17); s << x << " "; b += s.str(); };
  // camera
  if (ascii) { b += "3 1.5 2.5 3.5 7\n"; }
  else { put<std::uint8_t>(b, 3, little); for (float f : {1.5f, 2.5f, 3.5f}) put<float>(b, f, little); put<std::int8_t>(b, 7, little); }
  for (std::size_t i = 0; i < v.size(); ++i) {
    const auto& p = v[i];
    const int njunk = static_cast<int>(i % 3);
    if (ascii) {
      num(int(i)); dbl(p[2]); num(njunk); for (int k = 0; k < njunk; ++k) num(-k);
      dbl(static_cast<float>(p[0])); dbl(static_cast<float>(p[3])); dbl(p[1]); num(-1);
      dbl(static_cast<float>(p[4])); dbl(static_cast<float>(p[5])); num(200); b += "\n";
    } else {
      put<std::uint16_t>(b, static_cast<std::uint16_t>(i), little); put<double>(b, p[2], little);
      put<std::uint16_t>(b, static_cast<std::uint16_t>(njunk), little); for (int k = 0; k < njunk; ++k) put<std::int16_t>(b, -k, little);
      put<float>(b, static_cast<float>(p[0]), little); put<float>(b, static_cast<float>(p[3]), little); put<double>(b, p[1], little);
      put<std::int8_t>(b, -1, little); put<float>(b, static_cast<float>(p[4]), little); put<float>(b, static_cast<float>(p[5]), little);
      put<std::uint8_t>(b, 200, little);
    }
  }
  // faces: a triangle and a quad; edge element
  if (ascii) { b += "0 3 0 1 2\n1 4 0 1 2 3\n2 5 6\n"; }
  else {
    put<std::uint8_t>(b, 0, little); put<std::uint8_t>(b, 3, little); for (std::uint32_t k : {0u, 1u, 2u}) put<std::uint32_t>(b, k, little);
    put<std::uint8_t>(b, 1, little); put<std::uint8_t>(b, 4, little); for (std::uint32_t k : {0u, 1u, 2u, 3u}) put<std::uint32_t>(b, k, little);
    put<std::int32_t>(b, 2, little); put<std::int32_t>(b, 5, little); put<std::int32_t>(b, 6, little);
  }
  return h + b;
}

TEST(IoPly, HandmadeAllEncodingsMixedTypesListsExtraElements) {
  std::vector<std::array<double, 6>> v;
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-10, 10);
  for (int i = 0; i < 40; ++i) {
    Vec3 n = Vec3(u(rng), u(rng), u(rng)).normalized();
    v.push_back({u(rng), u(rng), u(rng), n.x(), n.y(), n.z()});
  }
  for (const char* fmt : {"ascii", "binary_little_endian", "binary_big_endian"}) {
    const std::string path = tmp_path(std::string("hand_") + fmt + ".ply");
    write_file(path, handmade_ply(fmt, v, std::string(fmt) != "binary_big_endian"));
    SCOPED_TRACE(path);
    const PointCloud c = read_points(path);
    ASSERT_EQ(c.size(), v.size());
    ASSERT_TRUE(c.has_normals());
    EXPECT_EQ(c.origin, Vec3::Zero());
    for (std::size_t i = 0; i < v.size(); ++i) {
      EXPECT_EQ(c.points[i].x(), static_cast<double>(static_cast<float>(v[i][0])));  // stored as float
      EXPECT_EQ(c.points[i].y(), v[i][1]);                                          // stored as double
      EXPECT_EQ(c.points[i].z(), v[i][2]);
      EXPECT_NEAR(c.normals[i].norm(), 1.0, 1e-12);
      EXPECT_NEAR(c.normals[i].x(), v[i][3], 1e-6);
    }
    const PolygonMesh m = read_mesh(path);
    ASSERT_EQ(m.num_faces(), 2u);
    EXPECT_EQ(m.faces[0], (std::vector<std::uint32_t>{0, 1, 2}));
    EXPECT_EQ(m.faces[1], (std::vector<std::uint32_t>{0, 1, 2, 3}));
    // Truncating the file anywhere in the data must be detected.
    const std::string full = slurp(path);
    write_file(tmp_path("trunc.ply"), full.substr(0, full.size() - 7));
    expect_error([&] { read_points(tmp_path("trunc.ply")); }, Status::BadFormat, tmp_path("trunc.ply"));
  }
}

// Binary bodies are streamed through a window of about 1 MB (issue 16): files of many windows, fixed-size
// records decoded in place (any property order and types, extra properties), records with a list property
// read value by value, both byte orders; and the end of the data found exactly (one byte short or over).
TEST(IoPly, StreamedBinaryBodiesOfManyWindows) {
  const int n = 150000;  // 150,000 records of 45 bytes: about 7 windows
  std::mt19937_64 rng(8);
  std::uniform_real_distribution<double> u(-100, 100);
  std::vector<std::array<double, 6>> v(n);
  for (auto& r : v) {
    const Vec3 nrm = Vec3(u(rng), u(rng), u(rng)).normalized();
    r = {u(rng), u(rng), u(rng), nrm.x(), nrm.y(), nrm.z()};
  }
  for (bool little : {true, false})
    for (bool with_list : {false, true}) {
      std::string b = std::string("ply\nformat ") + (little ? "binary_little_endian" : "binary_big_endian") +
                      " 1.0\nelement vertex " + std::to_string(n) +
                      "\nproperty float x\nproperty double nz\nproperty uchar red\nproperty double y\n" +
                      (with_list ? "property list uchar int junk\n" : "") +
                      "property double nx\nproperty double ny\nproperty double z\nproperty int flag\n"
                      "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
      for (int i = 0; i < n; ++i) {
        put<float>(b, static_cast<float>(v[i][0]), little);
        put<double>(b, v[i][5], little);
        put<std::uint8_t>(b, static_cast<std::uint8_t>(i), little);
        put<double>(b, v[i][1], little);
        if (with_list) {
          put<std::uint8_t>(b, static_cast<std::uint8_t>(i % 3), little);
          for (int k = 0; k < i % 3; ++k) put<std::int32_t>(b, -k, little);
        }
        put<double>(b, v[i][3], little);
        put<double>(b, v[i][4], little);
        put<double>(b, v[i][2], little);
        put<std::int32_t>(b, i, little);
      }
      put<std::uint8_t>(b, 3, little);
      for (int k : {0, 1, 2}) put<std::int32_t>(b, k, little);
      const std::string path = tmp_path(std::string("streamed_") + (little ? "le" : "be") + (with_list ? "_list" : "") + ".ply");
      write_file(path, b);
      SCOPED_TRACE(path);
      const PointCloud c = read_points(path);
      ASSERT_EQ(c.size(), static_cast<std::size_t>(n));
      ASSERT_TRUE(c.has_normals());
      for (int i = 0; i < n; i += 997) {
        EXPECT_EQ(c.points[i].x(), static_cast<double>(static_cast<float>(v[i][0])));
        EXPECT_EQ(c.points[i].y(), v[i][1]);
        EXPECT_EQ(c.points[i].z(), v[i][2]);
        EXPECT_NEAR((c.normals[i] - Vec3(v[i][3], v[i][4], v[i][5])).norm(), 0.0, 1e-12);
      }
      EXPECT_EQ(c.points.back().z(), v.back()[2]);
      EXPECT_EQ(read_mesh(path).faces.at(0), (std::vector<std::uint32_t>{0, 1, 2}));
      write_file(tmp_path("short.ply"), b.substr(0, b.size() - 1));
      expect_error([&] { read_points(tmp_path("short.ply")); }, Status::BadFormat, tmp_path("short.ply"));
      write_file(tmp_path("over.ply"), b + "x");
      expect_error([&] { read_points(tmp_path("over.ply")); }, Status::BadFormat, tmp_path("over.ply"));
    }
}

TEST(IoMesh, WriteReadAllFormatsExact) {
  for (const Vec3& origin : {Vec3(0, 0, 0), Vec3(600000, 4000000, 20000)}) {
    const PolygonMesh m = cube_mesh(origin);
    for (const auto& [name, enc] : std::vector<std::pair<std::string, FileEncoding>>{
             {"m.obj", FileEncoding::Ascii}, {"m.off", FileEncoding::Ascii}, {"ma.ply", FileEncoding::Ascii}, {"mb.ply", FileEncoding::Binary}}) {
      const std::string path = tmp_path(name);
      write_mesh(path, m, enc);
      SCOPED_TRACE(path);
      const PolygonMesh r = read_mesh(path);
      ASSERT_EQ(r.num_vertices(), 8u);
      ASSERT_EQ(r.faces, m.faces);
      for (std::size_t i = 0; i < 8; ++i) EXPECT_EQ(r.vertices[i] + r.origin, m.vertices[i] + m.origin);
      const PointCloud c = read_points(path);  // no sampling: the vertices
      ASSERT_EQ(c.size(), 8u);
      EXPECT_FALSE(c.has_normals());
      for (std::size_t i = 0; i < 8; ++i) EXPECT_EQ(c.points[i] + c.origin, m.vertices[i] + m.origin);
    }
  }
  expect_error([&] { write_mesh(tmp_path("m.stl"), cube_mesh(Vec3::Zero())); }, Status::BadFormat, tmp_path("m.stl"));
}

TEST(IoMesh, ObjIndexFormsAndNegativeIndices) {
  const std::string path = tmp_path("forms.obj");
  write_file(path,
             "# comment\nmtllib x.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0 1.0\nvt 0 0\nvn 0 0 1\n"
             "o thing\ng grp\nusemtl m\ns off\n"
             "f 1 2 3\nf 1/1 3/1 4/1\nf 1/1/1 2/1/1 3/1/1 4/1/1\nf 1//1 2//1 4//1\nf -4 -3 -2 -1\r\nl 1 2\n");
  const PolygonMesh m = read_mesh(path);
  ASSERT_EQ(m.num_vertices(), 4u);
  ASSERT_EQ(m.num_faces(), 5u);
  EXPECT_EQ(m.faces[0], (std::vector<std::uint32_t>{0, 1, 2}));
  EXPECT_EQ(m.faces[1], (std::vector<std::uint32_t>{0, 2, 3}));
  EXPECT_EQ(m.faces[2], (std::vector<std::uint32_t>{0, 1, 2, 3}));
  EXPECT_EQ(m.faces[3], (std::vector<std::uint32_t>{0, 1, 3}));
  EXPECT_EQ(m.faces[4], (std::vector<std::uint32_t>{0, 1, 2, 3}));
  write_file(tmp_path("badidx.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n");
  expect_error([&] { read_mesh(tmp_path("badidx.obj")); }, Status::BadFormat, tmp_path("badidx.obj"));
  write_file(tmp_path("zeroidx.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n");
  expect_error([&] { read_mesh(tmp_path("zeroidx.obj")); }, Status::BadFormat, tmp_path("zeroidx.obj"));
}

TEST(IoOff, VariantsCommentsAndCounts) {
  write_file(tmp_path("n.off"), "NOFF # normals\n# comment line\n3 1 0\n0 0 0 0 0 2\n1 0 0 0 0 2\n0 1 0 0 0 2\n3 0 1 2\n");
  PointCloud c = read_points(tmp_path("n.off"));
  ASSERT_EQ(c.size(), 3u);
  ASSERT_TRUE(c.has_normals());
  EXPECT_EQ(c.normals[1], Vec3(0, 0, 1));  // normalised
  write_file(tmp_path("c.off"), "COFF 4 2 0\n0 0 0 255 0 0 255\n1 0 0 255 0 0 255\n1 1 0 0 0 0 255\n0 1 0 1 1 1 1\n3 0 1 2\n3 0 2 3 1 0 0\n");
  c = read_points(tmp_path("c.off"));
  ASSERT_EQ(c.size(), 4u);
  EXPECT_FALSE(c.has_normals());
  EXPECT_EQ(c.points[2], Vec3(1, 1, 0));
  const PolygonMesh m = read_mesh(tmp_path("c.off"));
  ASSERT_EQ(m.num_faces(), 2u);
  EXPECT_EQ(m.faces[1], (std::vector<std::uint32_t>{0, 2, 3}));
  write_file(tmp_path("short.off"), "OFF\n4 0 0\n0 0 0\n1 0 0\n1 1 0\n");
  expect_error([&] { read_points(tmp_path("short.off")); }, Status::BadFormat, tmp_path("short.off"));
  write_file(tmp_path("shortf.off"), "OFF\n3 2 0\n0 0 0\n1 0 0\n1 1 0\n3 0 1 2\n");
  expect_error([&] { read_mesh(tmp_path("shortf.off")); }, Status::BadFormat, tmp_path("shortf.off"));
  write_file(tmp_path("hdr.off"), "FOO\n3 0 0\n0 0 0\n1 0 0\n1 1 0\n");
  expect_error([&] { read_points(tmp_path("hdr.off")); }, Status::BadFormat, tmp_path("hdr.off"));
}

TEST(IoText, ColumnsCommentsAndPtsCount) {
  write_file(tmp_path("seven.txt"), "# header\n3\n1 2 3 0 0 5 9\n4,5,6,0,3,0,9\n\n7 8 9 2 0 0 1\n");
  const PointCloud c = read_points(tmp_path("seven.txt"));
  ASSERT_EQ(c.size(), 3u);
  ASSERT_TRUE(c.has_normals());
  EXPECT_EQ(c.points[1], Vec3(4, 5, 6));
  EXPECT_EQ(c.normals[1], Vec3(0, 1, 0));
  write_file(tmp_path("four.xyz"), "1 2 3 4\n4 5 6 7\n");
  const PointCloud d = read_points(tmp_path("four.xyz"));
  ASSERT_EQ(d.size(), 2u);
  EXPECT_FALSE(d.has_normals());
  write_file(tmp_path("ragged.xyzn"), "1 2 3 0 0 1\n4 5 6\n");
  expect_error([&] { read_points(tmp_path("ragged.xyzn")); }, Status::BadFormat, tmp_path("ragged.xyzn"));
  write_file(tmp_path("word.xyz"), "1 2 3\n4 five 6\n");
  expect_error([&] { read_points(tmp_path("word.xyz")); }, Status::BadFormat, tmp_path("word.xyz"));
}

TEST(IoSampling, UniformByAreaWithFaceNormalsDeterministic) {
  // Two disjoint squares: area 1 (z = 0, normal +z) and area 4 (x = 10, normal -x, quad), written as OBJ.
  PolygonMesh m;
  m.vertices = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {10, 0, 0}, {10, 0, 2}, {10, 2, 2}, {10, 2, 0}};
  m.faces = {{0, 1, 2, 3}, {4, 5, 6, 7}};
  const std::string path = tmp_path("sample.obj");
  write_mesh(path, m);
  ReadParams params;
  params.sample_count = 20000;
  params.seed = 42;
  const PointCloud c = read_points(path, params);
  ASSERT_EQ(c.size(), 20000u);
  ASSERT_TRUE(c.has_normals());
  std::size_t on_small = 0;
  double mean_y_big = 0;
  for (std::size_t i = 0; i < c.size(); ++i) {
    const Vec3 g = c.points[i] + c.origin;
    if (g.z() == 0 && g.x() <= 1) {
      ++on_small;
      EXPECT_EQ(c.normals[i], Vec3(0, 0, 1));
      EXPECT_TRUE(g.x() >= 0 && g.y() >= 0 && g.y() <= 1);
    } else {
      ASSERT_NEAR(g.x(), 10.0, 1e-12);
      EXPECT_TRUE(g.y() >= 0 && g.y() <= 2 && g.z() >= 0 && g.z() <= 2);
      EXPECT_EQ(c.normals[i], Vec3(-1, 0, 0));
      mean_y_big += g.y();
    }
  }
  // Binomial(20000, 0.2): sd = 57, so +-300 is > 5 sigma.
  EXPECT_NEAR(static_cast<double>(on_small), 4000.0, 300.0);
  EXPECT_NEAR(mean_y_big / (c.size() - on_small), 1.0, 0.03);  // uniform over the big square
  const PointCloud again = read_points(path, params);
  EXPECT_EQ(again.points, c.points);
  params.seed = 43;
  const PointCloud other = read_points(path, params);
  EXPECT_NE(other.points, c.points);
}

// ---- LAS fixtures ----
std::string make_las(int minor, int format, std::uint16_t record_length, const std::vector<std::array<std::int32_t, 3>>& xyz,
                     const Vec3& scale, const Vec3& offset, bool legacy_count_zero = false) {
  const std::uint16_t header_size = minor >= 4 ? 375 : 227;
  const std::uint32_t vlr_bytes = 60;  // junk between header and points: the reader must use the offset
  std::string h(header_size, '\0');
  std::memcpy(&h[0], "LASF", 4);
  h[24] = 1;
  h[25] = static_cast<char>(minor);
  auto at = [&](std::size_t pos, auto v) { std::memcpy(&h[pos], &v, sizeof(v)); };
  at(94, header_size);
  at(96, std::uint32_t(header_size + vlr_bytes));
  at(100, std::uint32_t(1));
  h[104] = static_cast<char>(format);
  at(105, record_length);
  at(107, std::uint32_t(legacy_count_zero ? 0 : xyz.size()));
  for (int k = 0; k < 3; ++k) { at(131 + 8 * k, scale[k]); at(155 + 8 * k, offset[k]); }
  if (minor >= 4) at(247, std::uint64_t(xyz.size()));
  std::string body(vlr_bytes, '\x5a');
  for (const auto& p : xyz) {
    std::string rec(record_length, '\x7f');  // non-zero filler in the non-coordinate fields
    std::memcpy(&rec[0], p.data(), 12);
    body += rec;
  }
  return h + body;
}

TEST(IoLas, Las12Format3AndLas14Format6) {
  std::mt19937_64 rng(11);
  std::uniform_int_distribution<std::int32_t> ux(0, 2000000), uz(-1000, 90000);
  std::vector<std::array<std::int32_t, 3>> xyz;
  for (int i = 0; i < 3000; ++i) xyz.push_back({ux(rng), ux(rng), uz(rng)});
  const Vec3 scale(0.001, 0.001, 0.01), offset(500000, 4100000, 0);
  struct Case { int minor, format; std::uint16_t len; bool legacy_zero; };
  for (const Case& cs : {Case{2, 3, 34, false}, Case{4, 6, 30, true}, Case{4, 7, 40, false}}) {
    const std::string path = tmp_path("las" + std::to_string(cs.minor) + "_" + std::to_string(cs.format) + ".las");
    write_file(path, make_las(cs.minor, cs.format, cs.len, xyz, scale, offset, cs.legacy_zero));
    SCOPED_TRACE(path);
    const PointCloud c = read_points(path);
    ASSERT_EQ(c.size(), xyz.size());
    EXPECT_FALSE(c.has_normals());
    EXPECT_NE(c.origin.x(), 0.0);
    EXPECT_NE(c.origin.y(), 0.0);
    EXPECT_LT(c.points[0].cwiseAbs().maxCoeff(), 2000.0);  // local coordinates are small
    for (std::size_t i = 0; i < xyz.size(); ++i)
      for (int k = 0; k < 3; ++k) {
        const double expected = xyz[i][k] * scale[k] + offset[k];
        ASSERT_NEAR(c.points[i][k] + c.origin[k], expected, scale[k]) << i;
        ASSERT_EQ(c.points[i][k] + c.origin[k], expected) << "integer origin: the shift is exact";
      }
    // Truncated point data.
    const std::string full = slurp(path);
    write_file(tmp_path("trunc.las"), full.substr(0, full.size() - 10));
    expect_error([&] { read_points(tmp_path("trunc.las")); }, Status::BadFormat, tmp_path("trunc.las"));
  }
  std::string laz = make_las(2, 3, 34, xyz, scale, offset);
  laz[104] = static_cast<char>(3 | 0x80);
  write_file(tmp_path("laz.las"), laz);
  expect_error([&] { read_points(tmp_path("laz.las")); }, Status::BadFormat, tmp_path("laz.las"));
  write_file(tmp_path("short.las"), make_las(2, 3, 20, xyz, scale, offset));  // record too short for pdrf 3
  expect_error([&] { read_points(tmp_path("short.las")); }, Status::BadFormat, tmp_path("short.las"));
  write_file(tmp_path("notlas.las"), "LASX" + std::string(300, '\0'));
  expect_error([&] { read_points(tmp_path("notlas.las")); }, Status::BadFormat, tmp_path("notlas.las"));
}

TEST(IoLas, SharedUrbanTile) {
  const std::string path = std::string(HSR_SHARED_DATA_DIR) + "/cgal_urban.las";
  if (!fs::exists(path)) GTEST_SKIP() << path << " absent";
  const PointCloud c = read_points(path);
  ASSERT_EQ(c.size(), 13511u);
  const BBox box = bounding_box(c.points);
  EXPECT_NEAR(box.size().x(), 92.05, 0.01);
  EXPECT_NEAR(box.size().y(), 70.35, 0.01);
  EXPECT_NEAR(box.size().z(), 32.9, 0.01);
  EXPECT_NE(c.origin.x(), 0.0);
  EXPECT_NE(c.origin.y(), 0.0);
  EXPECT_LT(box.center().cwiseAbs().maxCoeff(), 1.0);  // centred on the local origin
  const std::string out = tmp_path("urban.ply");
  write_points(out, c, FileEncoding::Binary);
  const PointCloud r = read_points(out);
  ASSERT_EQ(r.size(), c.size());
  for (std::size_t i = 0; i < c.size(); ++i) {
    const Vec3 a = c.points[i] + c.origin, b = r.points[i] + r.origin;
    ASSERT_LE((a - b).norm(), 1e-6 * a.norm()) << i;
  }
}

TEST(IoErrors, MissingUnknownAndBadHeaders) {
  expect_error([&] { read_points(tmp_path("does_not_exist.ply")); }, Status::FileNotFound, tmp_path("does_not_exist.ply"));
  expect_error([&] { read_points(tmp_path("does_not_exist.las")); }, Status::FileNotFound, tmp_path("does_not_exist.las"));
  expect_error([&] { read_mesh(tmp_path("does_not_exist.obj")); }, Status::FileNotFound, tmp_path("does_not_exist.obj"));
  fs::create_directories(tmp_path("adir.ply"));
  expect_error([&] { read_points(tmp_path("adir.ply")); }, Status::FileNotFound, tmp_path("adir.ply"));
  write_file(tmp_path("x.stl"), "solid");
  expect_error([&] { read_points(tmp_path("x.stl")); }, Status::BadFormat, tmp_path("x.stl"));
  expect_error([&] { read_mesh(tmp_path("four.xyz")); }, Status::BadFormat, tmp_path("four.xyz"));
  write_file(tmp_path("bad1.ply"), "plx\nformat ascii 1.0\nelement vertex 1\nproperty float x\nend_header\n1\n");
  expect_error([&] { read_points(tmp_path("bad1.ply")); }, Status::BadFormat, tmp_path("bad1.ply"));
  write_file(tmp_path("bad2.ply"), "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n");  // no end_header
  expect_error([&] { read_points(tmp_path("bad2.ply")); }, Status::BadFormat, tmp_path("bad2.ply"));
  write_file(tmp_path("bad3.ply"), "ply\nformat ascii 1.0\nelement vertex 1\nproperty quad x\nend_header\n1\n");
  expect_error([&] { read_points(tmp_path("bad3.ply")); }, Status::BadFormat, tmp_path("bad3.ply"));
  write_file(tmp_path("bad4.ply"), "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nend_header\n1 2\n");
  expect_error([&] { read_points(tmp_path("bad4.ply")); }, Status::BadFormat, tmp_path("bad4.ply"));  // no z
  write_file(tmp_path("empty.ply"), "");
  expect_error([&] { read_points(tmp_path("empty.ply")); }, Status::BadFormat, tmp_path("empty.ply"));
}

TEST(IoErrors, CountsNotMatchingData) {
  const std::string hdr = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
  write_file(tmp_path("few.ply"), hdr + "0 0 0\n1 1 1\n");
  expect_error([&] { read_points(tmp_path("few.ply")); }, Status::BadFormat, tmp_path("few.ply"));
  write_file(tmp_path("many.ply"), hdr + "0 0 0\n1 1 1\n2 2 2\n3 3 3\n");
  expect_error([&] { read_points(tmp_path("many.ply")); }, Status::BadFormat, tmp_path("many.ply"));
  write_file(tmp_path("exact.ply"), hdr + "0 0 0\n1 1 1\n2 2 2\n");
  EXPECT_EQ(read_points(tmp_path("exact.ply")).size(), 3u);
  std::string bin = "ply\nformat binary_little_endian 1.0\nelement vertex 2\nproperty double x\nproperty double y\nproperty double z\nend_header\n";
  for (double v : {0.0, 1.0, 2.0, 3.0, 4.0}) put<double>(bin, v, true);  // one coordinate short
  write_file(tmp_path("trunc_bin.ply"), bin);
  expect_error([&] { read_points(tmp_path("trunc_bin.ply")); }, Status::BadFormat, tmp_path("trunc_bin.ply"));
}

TEST(IoErrors, BadValues) {
  write_file(tmp_path("nan.xyz"), "0 0 0\n1 nan 1\n");
  expect_error([&] { read_points(tmp_path("nan.xyz")); }, Status::BadInput, tmp_path("nan.xyz"));
  std::string bin = "ply\nformat binary_big_endian 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
  for (float v : {0.0f, 1.0f, 2.0f, 3.0f, INFINITY, 4.0f}) put<float>(bin, v, false);
  write_file(tmp_path("inf.ply"), bin);
  expect_error([&] { read_points(tmp_path("inf.ply")); }, Status::BadInput, tmp_path("inf.ply"));
  write_file(tmp_path("empty.xyz"), "# nothing\n\n");
  expect_error([&] { read_points(tmp_path("empty.xyz")); }, Status::BadInput, tmp_path("empty.xyz"));
  write_file(tmp_path("zero.ply"), "ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\nproperty float y\nproperty float z\nend_header\n");
  expect_error([&] { read_points(tmp_path("zero.ply")); }, Status::BadInput, tmp_path("zero.ply"));
  write_file(tmp_path("same.xyz"), "1 2 3\n1 2 3\n1 2 3\n");
  expect_error([&] { read_points(tmp_path("same.xyz")); }, Status::BadInput, tmp_path("same.xyz"));
  write_file(tmp_path("badnormal.xyzn"), "0 0 0 0 0 1\n1 1 1 inf 0 0\n");
  expect_error([&] { read_points(tmp_path("badnormal.xyzn")); }, Status::BadInput, tmp_path("badnormal.xyzn"));
  // A zero normal: the cloud loads without normals.
  write_file(tmp_path("zeronormal.xyzn"), "0 0 0 0 0 1\n1 1 1 0 0 0\n2 2 2 0 3 0\n");
  const PointCloud c = read_points(tmp_path("zeronormal.xyzn"));
  EXPECT_EQ(c.size(), 3u);
  EXPECT_FALSE(c.has_normals());
  EXPECT_TRUE(c.normals.empty());
}

TEST(IoErrors, FailingWriteLeavesNothingBehind) {
  PolygonMesh bad = cube_mesh(Vec3::Zero());
  bad.faces.push_back({0, 1, 99});
  const std::string dir = tmp_path("failwrite");
  fs::remove_all(dir);
  fs::create_directories(dir);
  for (const char* name : {"/a.obj", "/a.ply", "/a.off"}) {
    expect_error([&] { write_mesh(dir + name, bad, FileEncoding::Binary); }, Status::BadInput, dir + name);
    EXPECT_FALSE(fs::exists(dir + name));
  }
  PointCloud nan_cloud = random_cloud(10, false, Vec3::Zero(), 1);
  nan_cloud.points[7].y() = NAN;
  expect_error([&] { write_points(dir + "/p.xyz", nan_cloud); }, Status::BadInput, dir + "/p.xyz");
  EXPECT_FALSE(fs::exists(dir + "/p.xyz"));
  // Overwriting: a failing write keeps the old file intact.
  write_mesh(dir + "/keep.off", cube_mesh(Vec3::Zero()));
  const std::string before = slurp(dir + "/keep.off");
  expect_error([&] { write_mesh(dir + "/keep.off", bad); }, Status::BadInput, dir + "/keep.off");
  EXPECT_EQ(slurp(dir + "/keep.off"), before);
  // .xyzn needs normals.
  expect_error([&] { write_points(dir + "/nn.xyzn", random_cloud(5, false, Vec3::Zero(), 2)); }, Status::BadInput, dir + "/nn.xyzn");
  // No temporaries left anywhere in the folder.
  std::size_t entries = 0;
  for (const auto& e : fs::directory_iterator(dir)) { ++entries; EXPECT_EQ(e.path().filename(), "keep.off"); }
  EXPECT_EQ(entries, 1u);
  expect_error([&] { write_points(dir + "/no/such/dir/p.ply", random_cloud(5, false, Vec3::Zero(), 2)); }, Status::FileNotFound,
               dir + "/no/such/dir/p.ply");
}

TEST(IoSharedData, CountsAndNormalsMatchManifest) {
  const std::string dir = HSR_SHARED_DATA_DIR;
  std::ifstream manifest(dir + "/MANIFEST.tsv");
  if (!manifest) GTEST_SKIP() << dir << "/MANIFEST.tsv absent";
  std::string line;
  std::getline(manifest, line);
  std::vector<std::string> header;
  auto split = [](const std::string& s) {
    std::vector<std::string> out;
    std::stringstream ss(s);
    std::string f;
    while (std::getline(ss, f, '\t')) out.push_back(f);
    return out;
  };
  header = split(line);
  const auto col = [&](const std::string& name) {
    return static_cast<std::size_t>(std::find(header.begin(), header.end(), name) - header.begin());
  };
  const std::size_t c_file = col("file"), c_points = col("points"), c_normals = col("has_normals");
  ASSERT_LT(std::max({c_file, c_points, c_normals}), header.size());
  int checked = 0;
  while (std::getline(manifest, line)) {
    const auto f = split(line);
    if (f.size() <= std::max({c_file, c_points, c_normals})) continue;
    const std::string path = dir + "/" + f[c_file];
    if (!fs::exists(path)) continue;
    SCOPED_TRACE(path);
    const PointCloud c = read_points(path);
    EXPECT_EQ(c.size(), std::stoull(f[c_points]));
    EXPECT_EQ(c.has_normals(), f[c_normals] == "yes");
    ++checked;
  }
  if (checked == 0) GTEST_SKIP() << "no shared data files present";
}

TEST(IoSharedData, MeshFilesAndSampling) {
  const std::string off = std::string(HSR_SHARED_DATA_DIR) + "/cgal_fandisk.off";
  const std::string ply = std::string(HSR_SHARED_DATA_DIR) + "/stanford_bun_zipper.ply";
  if (!fs::exists(off) || !fs::exists(ply)) GTEST_SKIP() << "fandisk / bunny absent";
  const PolygonMesh fandisk = read_mesh(off);
  EXPECT_EQ(fandisk.num_vertices(), 6475u);
  EXPECT_EQ(fandisk.num_faces(), 12946u);
  const PolygonMesh bunny = read_mesh(ply);
  EXPECT_EQ(bunny.num_vertices(), 35947u);
  EXPECT_EQ(bunny.num_faces(), 69451u);
  ReadParams params;
  params.sample_count = 5000;
  const PointCloud s = read_points(off, params);
  ASSERT_EQ(s.size(), 5000u);
  ASSERT_TRUE(s.has_normals());
  const BBox mesh_box = bounding_box(fandisk.vertices), sample_box = bounding_box(s.points);
  const double eps = 1e-12 * mesh_box.diagonal();
  EXPECT_TRUE((sample_box.min.array() >= mesh_box.min.array() - eps).all() &&
              (sample_box.max.array() <= mesh_box.max.array() + eps).all());
  EXPECT_LT((sample_box.size() - mesh_box.size()).norm(), 0.05 * mesh_box.diagonal());
}
