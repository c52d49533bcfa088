// The CLI on an E57 file of three scans with poses: `hsr reconstruct` takes each scan's pose translation as a
// scanner position and writes the same bytes as on the same points given as PLY with --scanner for each pose;
// a broken E57 is one line `hsr: io: ...`, a non-zero exit and no output file.
#include "io/e57_writer.h"
#include "io/io.h"

#include "test_util.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <filesystem>
#include <fstream>

namespace hsr {
namespace {

/// A closed box room 4 x 3 x 2.5 m sampled on a 5 cm grid, split into three scans by wall.
std::vector<E57WriteScan> room_scans() {
  std::vector<E57WriteScan> scans(3);
  const double step = 0.05;
  const Vec3 size(4, 3, 2.5);
  int k = 0;
  for (int axis = 0; axis < 3; ++axis)
    for (int side = 0; side < 2; ++side) {
      const int u = (axis + 1) % 3, v = (axis + 2) % 3;
      for (double a = step / 2; a < size[u]; a += step)
        for (double b = step / 2; b < size[v]; b += step) {
          Vec3 p;
          p[axis] = side * size[axis];
          p[u] = a;
          p[v] = b;
          scans[static_cast<std::size_t>(k % 3)].points.push_back(p);
        }
      ++k;
    }
  // Poses whose rotations are exact (the identity, 180 degrees about z and about x), so every scan's points
  // in the file frame are exact: local = R^T (p - t).
  const Vec3 t[3] = {Vec3(1, 1, 1.25), Vec3(3, 2, 1.5), Vec3(2, 1.5, 1)};
  const std::array<double, 4> q[3] = {{1, 0, 0, 0}, {0, 0, 0, 1}, {0, 1, 0, 0}};
  for (std::size_t s = 0; s < 3; ++s) {
    scans[s].name = "scan" + std::to_string(s);
    scans[s].translation = t[s];
    scans[s].rotation = q[s];
    for (Vec3& p : scans[s].points) {
      const Vec3 d = p - t[s];
      p = s == 0 ? d : s == 1 ? Vec3(-d.x(), -d.y(), d.z()) : Vec3(d.x(), -d.y(), -d.z());
    }
  }
  return scans;
}

TEST(E57Cli, ThreeScansWithPosesGiveTheMeshOfThePlyWithScanners) {
  const auto dir = test::scratch_dir("e57_cli");
  const std::string e57 = (dir / "room.e57").string(), ply = (dir / "room.ply").string();
  const std::vector<E57WriteScan> scans = room_scans();
  write_e57(e57, scans);
  std::vector<Vec3> scanners;
  const PointCloud cloud = read_points(e57, {}, scanners);
  ASSERT_EQ(scanners.size(), 3u);
  write_points(ply, cloud);  // binary doubles: the same points, bit for bit
  std::string positions;
  for (const Vec3& s : scanners)
    positions += (positions.empty() ? "" : ";") + std::to_string(s.x()) + "," + std::to_string(s.y()) + "," + std::to_string(s.z());
  const auto a = test::run_cli("-q reconstruct " + e57 + " -o " + (dir / "e57.obj").string());
  const auto b = test::run_cli("-q reconstruct " + ply + " --scanner '" + positions + "' -o " + (dir / "ply.obj").string());
  ASSERT_EQ(a.exit_code, 0) << a.output;
  ASSERT_EQ(b.exit_code, 0) << b.output;
  const std::string mesh = test::read_file(dir / "e57.obj");
  std::size_t faces = 0;
  for (std::size_t at = mesh.find("\nf "); at != std::string::npos; at = mesh.find("\nf ", at + 1)) ++faces;
  EXPECT_EQ(faces, 6u) << mesh;  // the room's six walls
  EXPECT_TRUE(mesh == test::read_file(dir / "ply.obj")) << "the E57 run and the PLY run with --scanner differ";
  // The run knew the three scanners (the report's structure counts them), the PLY run without --scanner none.
  const auto scanners_in_report = [&](const std::string& input, const std::string& name) {
    const auto r = test::run_cli("-q reconstruct " + input + " -o " + (dir / (name + ".obj")).string() + " --report " +
                                 (dir / (name + ".json")).string());
    EXPECT_EQ(r.exit_code, 0) << r.output;
    const nlohmann::json flat = nlohmann::json::parse(test::read_file(dir / (name + ".json"))).flatten();
    for (auto it = flat.begin(); it != flat.end(); ++it)
      if (it.key().size() > 9 && it.key().substr(it.key().size() - 9) == "/scanners" && it.value().is_number())
        return it.value().get<int>();
    return -1;
  };
  EXPECT_EQ(scanners_in_report(e57, "e57_report"), 3);
  EXPECT_EQ(scanners_in_report(ply, "ply_report"), 0);
}

TEST(E57Cli, BrokenE57IsOneLineAndNoOutput) {
  const auto dir = test::scratch_dir("e57_broken");
  std::string bytes = e57_file_bytes(room_scans());
  bytes.resize(bytes.size() / 2);
  const std::string path = (dir / "cut.e57").string();
  std::ofstream(path, std::ios::binary) << bytes;
  const std::string out = (dir / "cut.obj").string();
  const auto r = test::run_cli("reconstruct " + path + " -o " + out);
  EXPECT_NE(r.exit_code, 0);
  EXPECT_EQ(r.output.rfind("hsr: io: ", 0), 0u) << r.output;
  EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
  EXPECT_FALSE(std::filesystem::exists(out));
}

}  // namespace
}  // namespace hsr
