// Partition variants on real scans and synth models, side by side in one process (issue 17's ablation).
//
// usage: bench_partition_scans [--variant NAME=SPEC]... [--data DIR]... [--synth all|m1,m2] [--files f1,f2]
//                              [--csv out.tsv] [--quiet]
// Each input is read once and taken through the stages before the partition once (default parameters, as
// `hsr reconstruct`; meshes (.off) are sampled with 50,000 points, as bench/partition/real_files.sh); then
// every variant runs the partition (CPU time of that stage alone), the extraction and the evaluation.
// SPEC: a partitioner name, then comma-separated key=value overrides of PartitionParams:
//   those of partition_options.h, and levels (0: every polygon on level 1), speeds (0: every speed 1),
//   adjacency (0: none given).
// Default variants: exhaustive, bsp, kinetic, hierarchical.
// Prints one row per (input, variant), then per variant: inputs with a valid mesh, total cells, mean cells,
// total partition facets, mean mesh facets, mean p2m (% of the bbox diagonal) and total partition CPU seconds,
// over the inputs where every variant gave a valid mesh. The load average is printed at start and end.
#include "core/error.h"
#include "core/log.h"
#include "eval/eval.h"
#include "extraction/extraction.h"
#include "hulls/hulls.h"
#include "io/io.h"
#include "partition_options.h"
#include "partition/partition.h"
#include "recovery/recovery.h"
#include "structure/structure.h"
#include "synth/synth.h"
#include "visibility/visibility.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

using namespace hsr;
namespace fs = std::filesystem;

namespace {

struct Variant {
  std::string name;
  PartitionParams params;
  bool levels = true, speeds = true, adjacency = true;
};

std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, sep))
    if (!item.empty()) out.push_back(item);
  return out;
}

Variant parse_variant(const std::string& name, const std::string& spec) {
  Variant v;
  v.name = name;
  const auto parts = split(spec, ',');
  if (parts.empty()) throw Error(Status::BadInput, "bench", "empty variant spec for " + name);
  v.params.method = parse_partitioner(parts[0]);
  for (std::size_t i = 1; i < parts.size(); ++i) {
    const auto eq = parts[i].find('=');
    if (eq == std::string::npos) throw Error(Status::BadInput, "bench", "expected key=value: " + parts[i]);
    const std::string key = parts[i].substr(0, eq);
    const int value = std::stoi(parts[i].substr(eq + 1));
    if (bench::apply_partition_option(v.params, key, value)) continue;
    if (key == "levels") v.levels = value != 0;
    else if (key == "speeds") v.speeds = value != 0;
    else if (key == "adjacency") v.adjacency = value != 0;
    else throw Error(Status::BadInput, "bench", "unknown variant key " + key);
  }
  return v;
}

// What the stages before the partition give for one input.
struct Prepared {
  std::string name;
  PointCloud cloud;  // normals flipped to their plane's outward side, as the pipeline does
  SceneStructure structure;
  PartitionInput input;
};

Prepared prepare(const std::string& name, const PointCloud& raw) {
  Prepared p;
  p.name = name;
  p.structure = run_structure(raw, StructureParams{});
  const VisibilityResult visibility = run_visibility(raw, p.structure, VisibilityParams{});
  p.cloud = raw;
  p.cloud.normals = p.structure.normals;
  orient_inlier_normals(p.structure, visibility, p.cloud.normals);
  const RecoveryResult recovery = run_recovery(p.cloud, p.structure, RecoveryParams{});
  p.input.polygons = run_hulls(p.cloud, p.structure, visibility, recovery, HullsParams{});
  p.input.points_bbox = bounding_box(p.cloud.points);
  p.input.adjacent_planes = polygon_adjacency(p.structure, recovery);
  return p;
}

struct Row {
  bool ok = false;
  std::string error;
  std::size_t cells = 0, facets = 0, mesh_faces = 0;
  bool valid = false;
  double p2m = 0, cpu = 0;
};

Row run_variant(const Prepared& in, const Variant& v) {
  Row r;
  PartitionInput pin = in.input;
  for (ConvexPolygon& poly : pin.polygons) {
    if (!v.levels) poly.level = 1;
    if (!v.speeds) poly.speed = 1;
  }
  if (!v.adjacency) pin.adjacent_planes.clear();
  PartitionParams params = v.params;
  params.exact_volumes = false;
  try {
    const std::clock_t c0 = std::clock();
    const CellComplex complex = run_partition(pin, params);
    r.cpu = static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC;
    r.cells = complex.cells.size();
    r.facets = complex.facets.size();
    ExtractionInput ein;
    ein.complex = &complex;
    ein.cloud = &in.cloud;
    ein.point_plane = &in.structure.point_plane;
    ein.spacing = in.structure.spacing;
    const ExtractionResult ex = run_extraction(ein, ExtractionParams{});
    EvalParams ep;
    ep.mesh_samples = 1000;  // p2m (points -> mesh) does not use them
    const EvalResult ev = run_eval(in.cloud, ex.mesh, nullptr, ep);
    r.mesh_faces = ex.mesh.num_faces();
    r.valid = ev.validity.valid();
    r.p2m = 100 * ev.accuracy.p2m_mean;
    r.ok = true;
  } catch (const Error& e) {
    r.error = e.one_line();
  }
  return r;
}

std::string uptime() {
  std::ifstream f("/proc/loadavg");
  std::string a, b, c;
  f >> a >> b >> c;
  return a + " " + b + " " + c;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<Variant> variants;
  std::vector<std::string> dirs, files, synth_models;
  std::string csv;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) { std::fprintf(stderr, "missing value for %s\n", a.c_str()); std::exit(2); }
      return argv[++i];
    };
    if (a == "--variant") {
      const std::string s = next();
      const auto eq = s.find('=');
      variants.push_back(eq == std::string::npos ? parse_variant(s, s) : parse_variant(s.substr(0, eq), s.substr(eq + 1)));
    } else if (a == "--data") dirs.push_back(next());
    else if (a == "--files") files = split(next(), ',');
    else if (a == "--synth") {
      const std::string s = next();
      synth_models = s == "all" ? synth_model_names() : split(s, ',');
    } else if (a == "--csv") csv = next();
    else if (a == "--quiet") log::set_level(log::Level::Quiet);
    else { std::fprintf(stderr, "unknown option %s\n", a.c_str()); return 2; }
  }
  log::set_level(log::Level::Quiet);
  if (variants.empty())
    for (const char* m : {"exhaustive", "bsp", "kinetic", "hierarchical"}) variants.push_back(parse_variant(m, m));
  std::vector<std::pair<std::string, std::string>> inputs;  // (display name, path or synth:model)
  for (const std::string& d : dirs) {
    std::vector<fs::path> found;
    for (const auto& e : fs::directory_iterator(d)) {
      const std::string ext = e.path().extension().string();
      if (ext == ".ply" || ext == ".xyz" || ext == ".las" || ext == ".off") found.push_back(e.path());
    }
    std::sort(found.begin(), found.end());
    for (const fs::path& f : found) {
      const std::string stem = f.filename().string();
      if (!files.empty() && std::find(files.begin(), files.end(), stem) == files.end()) continue;
      inputs.emplace_back(stem, f.string());
    }
  }
  for (const std::string& m : synth_models) inputs.emplace_back("synth_" + m, "synth:" + m);
  std::printf("# load average at start: %s\n", uptime().c_str());
  std::printf("%-30s %-22s %7s %8s %6s %6s %8s %8s\n", "input", "variant", "cells", "facets", "mesh", "valid", "p2m%",
              "cpu_s");
  std::map<std::string, std::vector<Row>> rows;  // variant -> row per input
  for (const auto& [name, path] : inputs) {
    Prepared prep;
    try {
      PointCloud raw;
      if (path.rfind("synth:", 0) == 0) {
        raw = run_synth(path.substr(6)).cloud;
      } else {
        ReadParams rp;
        if (fs::path(path).extension() == ".off") rp.sample_count = 50000;
        raw = read_points(path, rp);
      }
      prep = prepare(name, raw);
    } catch (const Error& e) {
      std::printf("%-30s (stages before the partition failed: %s)\n", name.c_str(), e.one_line().c_str());
      for (const Variant& v : variants) rows[v.name].push_back(Row{});
      continue;
    }
    for (const Variant& v : variants) {
      const Row r = run_variant(prep, v);
      rows[v.name].push_back(r);
      if (r.ok)
        std::printf("%-30s %-22s %7zu %8zu %6zu %6s %8.3f %8.3f\n", name.c_str(), v.name.c_str(), r.cells, r.facets,
                    r.mesh_faces, r.valid ? "yes" : "NO", r.p2m, r.cpu);
      else
        std::printf("%-30s %-22s FAILED %s\n", name.c_str(), v.name.c_str(), r.error.c_str());
      std::fflush(stdout);
    }
  }
  std::vector<std::size_t> common;  // inputs where every variant gave a valid mesh
  for (std::size_t i = 0; i < inputs.size(); ++i) {
    bool all = true;
    for (const Variant& v : variants) all &= rows[v.name][i].ok && rows[v.name][i].valid;
    if (all) common.push_back(i);
  }
  std::printf("\n# load average at end: %s\n", uptime().c_str());
  std::printf("Over the %zu of %zu inputs where every variant gave a valid mesh:\n", common.size(), inputs.size());
  std::printf("%-22s %6s %9s %9s %10s %10s %9s %9s\n", "variant", "valid", "cells", "mean", "facets", "mesh_mean",
              "p2m%", "cpu_s");
  for (const Variant& v : variants) {
    const auto& rs = rows[v.name];
    std::size_t valid = 0;
    for (const Row& r : rs) valid += r.ok && r.valid;
    double cells = 0, facets = 0, mesh = 0, p2m = 0, cpu = 0;
    for (std::size_t i : common) {
      cells += static_cast<double>(rs[i].cells);
      facets += static_cast<double>(rs[i].facets);
      mesh += static_cast<double>(rs[i].mesh_faces);
      p2m += rs[i].p2m;
      cpu += rs[i].cpu;
    }
    const double n = std::max<double>(1, static_cast<double>(common.size()));
    std::printf("%-22s %6zu %9.0f %9.1f %10.0f %10.1f %9.4f %9.3f\n", v.name.c_str(), valid, cells, cells / n, facets,
                mesh / n, p2m / n, cpu);
  }
  if (!csv.empty()) {
    std::ofstream out(csv);
    out << "input\tvariant\tcells\tfacets\tmesh_faces\tvalid\tp2m_percent\tcpu_s\n";
    for (std::size_t i = 0; i < inputs.size(); ++i)
      for (const Variant& v : variants) {
        const Row& r = rows[v.name][i];
        out << inputs[i].first << '\t' << v.name << '\t' << r.cells << '\t' << r.facets << '\t' << r.mesh_faces << '\t'
            << (r.ok && r.valid ? "yes" : "no") << '\t' << r.p2m << '\t' << r.cpu << '\n';
      }
  }
  return 0;
}
