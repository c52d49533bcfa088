#include "pipeline.h"

#include "core/error.h"
#include "core/log.h"
#include "hulls/hulls.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

namespace hsr {

namespace {

std::string fmt_seconds(double s) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2f s", s);
  return buf;
}

/// Times one stage, logs it, records it in the report, and re-labels foreign exceptions with the stage.
template <class F>
auto timed_stage(const char* name, nlohmann::json& report, F&& body) {
  const double t0 = log::now_seconds();
  try {
    auto result = body();
    const double dt = log::now_seconds() - t0;
    report["seconds"][name] = dt;
    log::verbose(std::string("[") + name + "] done in " + fmt_seconds(dt));
    return result;
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    throw Error(Status::Internal, name, e.what());
  }
}

/// A volume needs planes in at least two directions; anything less cannot enclose anything but the box.
void check_planes_can_enclose(const SceneStructure& s) {
  if (s.planes.empty()) throw Error(Status::NoPlanes, "structure", "no plane found");
  const Vec3& n0 = s.planes.front().plane.normal;
  for (const auto& p : s.planes)
    if (std::abs(p.plane.normal.dot(n0)) < std::cos(5.0 * M_PI / 180.0)) return;
  throw Error(Status::DegenerateInput, "structure",
              std::to_string(s.planes.size()) + " plane(s) found, all parallel (points on one plane?): "
              "no volume can be enclosed");
}

}  // namespace

PipelineResult run_pipeline(const PointCloud& input, const PipelineParams& params) {
  PipelineResult out;
  nlohmann::json& report = out.report;
  report["version"] = HSR_VERSION;
  report["counts"]["points"] = input.size();
  const double start = log::now_seconds();
  const bool dump = !params.dump_dir.empty();

  // Stage 1: structure.
  const SceneStructure structure = timed_stage("structure", report, [&] {
    return run_structure(input, params.structure);
  });
  report["parameters"]["structure"] = structure.params;
  report["counts"]["planes"] = structure.planes.size();
  log::info("[structure] " + std::to_string(structure.planes.size()) + " planes, spacing r = " +
            std::to_string(structure.spacing));
  if (dump) write_structure_dump(input, structure, params.dump_dir);
  check_planes_can_enclose(structure);

  // The cloud the later stages see: same points, normals from stage 1 (input's or estimated).
  PointCloud cloud = input;
  cloud.normals = structure.normals;

  // Stage 4: hulls (visibility and recovery are not built yet: every plane is level 1, speed 1).
  const std::vector<ConvexPolygon> polygons = timed_stage("hulls", report, [&] {
    return run_hulls(cloud, structure);
  });
  report["counts"]["polygons"] = polygons.size();

  // Stage 5: partition.
  PartitionInput pin;
  pin.polygons = polygons;
  pin.points_bbox = bounding_box(cloud.points);
  const CellComplex complex = timed_stage("partition", report, [&] {
    return run_partition(pin, params.partition);
  });
  report["parameters"]["partition"] = {{"method", partitioner_name(params.partition.method)},
                                       {"bbox_margin", params.partition.bbox_margin}};
  report["counts"]["cells"] = complex.cells.size();
  report["counts"]["partition_facets"] = complex.facets.size();
  log::info("[partition] " + std::string(partitioner_name(params.partition.method)) + ": " +
            std::to_string(complex.cells.size()) + " cells, " + std::to_string(complex.facets.size()) + " facets");
  if (dump) write_partition_dump(complex, (std::filesystem::path(params.dump_dir) / "partition.ply").string());

  // Stage 6: extraction.
  ExtractionInput ein;
  ein.complex = &complex;
  ein.cloud = &cloud;
  ein.point_plane = &structure.point_plane;
  ein.spacing = structure.spacing;
  ExtractionResult extraction = timed_stage("extraction", report, [&] {
    return run_extraction(ein, params.extraction);
  });
  report["parameters"]["extraction"] = {{"lambda", params.extraction.lambda},
                                        {"merge_coplanar", params.extraction.merge_coplanar}};
  report["counts"]["inside_cells"] =
      static_cast<std::size_t>(std::count(extraction.inside.begin(), extraction.inside.end(), true));
  report["counts"]["surface_facets"] = extraction.surface_facets;
  if (dump)
    write_labels_dump(complex, extraction.inside, (std::filesystem::path(params.dump_dir) / "labels.ply").string());
  out.mesh = std::move(extraction.mesh);
  out.mesh.origin = input.origin;

  // Stage 7: evaluation — the output is checked before anyone writes it.
  out.eval = timed_stage("eval", report, [&] { return run_eval(cloud, out.mesh, params.truth, params.eval); });
  const nlohmann::json ej = to_json(out.eval);
  report["validity"] = ej["validity"];
  report["accuracy"] = ej["accuracy"];
  report["counts"]["output_vertices"] = out.mesh.num_vertices();
  report["counts"]["output_faces"] = out.mesh.num_faces();
  report["seconds"]["total"] = log::now_seconds() - start;
  report["peak_memory_mb"] = log::peak_memory_mb();

  if (!out.eval.validity.valid()) {
    report["forced"] = params.force;
    const std::string what = "output mesh is not valid (" + out.eval.validity.summary() + ")";
    if (!params.force) throw Error(Status::InvalidOutput, "extraction", what + "; --force writes it anyway");
    log::warn(what + "; written anyway because of --force");
  }
  return out;
}

}  // namespace hsr
