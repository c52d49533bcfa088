// The contract the readers of stage io must keep on any input bytes (fuzz_reader.cpp and the regression test
// tests/reliability/fuzz_regression_test.cpp): a reader either returns or throws hsr::Error from stage "io"
// with BadFormat or BadInput (never another exception, never FileNotFound for an existing file); a returned
// cloud is non-empty and finite, normals absent or one unit normal per point, and survives a binary PLY round
// trip through the project's writer (same count, same global coordinates up to rounding relative to the
// cloud's magnitude); for mesh formats (ply, off, obj) read_mesh's faces index existing vertices and sampling
// on them works. A violation throws ReaderContractViolation.
#pragma once

#include "core/error.h"
#include "io/io.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace hsr::fuzz {

struct ReaderContractViolation : std::logic_error {
  using std::logic_error::logic_error;
};

namespace contract_detail {

[[noreturn]] inline void violation(const std::string& what) { throw ReaderContractViolation(what); }

inline void check_error(const hsr::Error& e) {
  if (e.stage() != "io") violation("error from stage '" + e.stage() + "': " + e.one_line());
  if (e.status() != hsr::Status::BadFormat && e.status() != hsr::Status::BadInput)
    violation(std::string("unexpected status ") + hsr::status_name(e.status()) + ": " + e.one_line());
}

inline void check_cloud(const hsr::PointCloud& c) {
  if (c.empty()) violation("empty cloud returned");
  if (!c.normals.empty() && c.normals.size() != c.points.size()) violation("normals count differs from points");
  for (const auto& p : c.points)
    if (!p.allFinite()) violation("non-finite point returned");
  for (const auto& n : c.normals)
    if (!n.allFinite() || std::abs(n.norm() - 1.0) > 1e-6) violation("normal not of unit length");
  if (!c.origin.allFinite()) violation("non-finite origin");
}

inline void round_trip(const hsr::PointCloud& c, const std::string& scratch_ply) {
  hsr::write_points(scratch_ply, c, hsr::FileEncoding::Binary);
  const hsr::PointCloud back = hsr::read_points(scratch_ply);
  if (back.size() != c.size() || back.has_normals() != c.has_normals()) violation("round trip changed the counts");
  // Local coordinates are relative to one origin per cloud, so the rounding of a global coordinate is
  // relative to the largest magnitude in the cloud (origin included), not to the point's own.
  double magnitude = c.origin.cwiseAbs().maxCoeff() + back.origin.cwiseAbs().maxCoeff();
  for (const auto& p : c.points) magnitude = std::max(magnitude, (p + c.origin).cwiseAbs().maxCoeff());
  for (std::size_t i = 0; i < c.size(); ++i) {
    const hsr::Vec3 a = c.points[i] + c.origin, b = back.points[i] + back.origin;
    if (!((a - b).cwiseAbs().maxCoeff() <= 1e-12 * magnitude)) violation("round trip moved a point");
  }
}

}  // namespace contract_detail

/// Reads `path` (its extension picks the reader) every way the contract covers; `scratch_ply` is a path the
/// round trip may overwrite. Throws ReaderContractViolation on a violation; returns normally otherwise.
inline void check_reader_contract(const std::string& path, const std::string& scratch_ply) {
  using namespace contract_detail;
  try {
    const hsr::PointCloud cloud = hsr::read_points(path);
    check_cloud(cloud);
    round_trip(cloud, scratch_ply);
  } catch (const hsr::Error& e) {
    check_error(e);
  }
  const std::string ext = hsr::file_extension(path);
  if (ext == "ply" || ext == "off" || ext == "obj") {
    try {
      const hsr::PolygonMesh mesh = hsr::read_mesh(path);
      for (const auto& f : mesh.faces) {
        if (f.size() < 3) violation("face with fewer than 3 vertices");
        for (auto v : f)
          if (v >= mesh.vertices.size()) violation("face index out of range");
      }
    } catch (const hsr::Error& e) {
      check_error(e);
    }
    try {
      hsr::ReadParams rp;
      rp.sample_count = 64;
      check_cloud(hsr::read_points(path, rp));
    } catch (const hsr::Error& e) {
      check_error(e);
    }
  }
}

}  // namespace hsr::fuzz
