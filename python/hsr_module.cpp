// The Python module `hsr` (pybind11): numpy arrays in and out, the whole pipeline or its stages one by one.
// See README.md "Python" and python/tests/. Coordinates: numpy arrays hold global coordinates; clouds with
// large coordinates are shifted to a local origin inside (as the file readers do) and shifted back on output.
// Errors: hsr::Error becomes hsr.Error (a RuntimeError) carrying the one-line message "stage: problem" and
// `status` and `stage` attributes (status e.g. "bad-input", as core/error.h status_name).
#include "core/error.h"
#include "core/face_class.h"
#include "core/log.h"
#include "eval/eval.h"
#include "io/io.h"
#include "pipeline/pipeline.h"
#include "report/report.h"
#include "synth/synth.h"

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <map>
#include <memory>
#include <string>

namespace py = pybind11;
using namespace hsr;

void bind_driver(py::module_& m);  // driver_bindings.cpp: the steps of hsr batch and hsr city, for the Dask drivers

namespace {

using DoubleArray = py::array_t<double, py::array::c_style | py::array::forcecast>;

// ------------------------------------------------------------------------------------------ conversions

/// N×3 numpy array viewing a vector's memory, which the array then owns (no copy of the data).
py::array_t<double> to_numpy(std::vector<Vec3>&& v) {
  auto* owner = new std::vector<Vec3>(std::move(v));
  py::capsule free_when_done(owner, [](void* p) { delete static_cast<std::vector<Vec3>*>(p); });
  static_assert(sizeof(Vec3) == 3 * sizeof(double), "Vec3 must be three packed doubles");
  return py::array_t<double>({static_cast<py::ssize_t>(owner->size()), py::ssize_t{3}},
                             {static_cast<py::ssize_t>(sizeof(Vec3)), static_cast<py::ssize_t>(sizeof(double))},
                             reinterpret_cast<const double*>(owner->data()), free_when_done);
}

template <class T>
py::array_t<T> to_numpy_1d(std::vector<T>&& v) {
  auto* owner = new std::vector<T>(std::move(v));
  py::capsule free_when_done(owner, [](void* p) { delete static_cast<std::vector<T>*>(p); });
  return py::array_t<T>({static_cast<py::ssize_t>(owner->size())}, {static_cast<py::ssize_t>(sizeof(T))},
                        owner->data(), free_when_done);
}

py::array_t<double> vec3(const Vec3& v) { return to_numpy_1d(std::vector<double>{v.x(), v.y(), v.z()}); }

std::vector<Vec3> to_vec3s(const py::handle& obj, const char* what) {
  DoubleArray a;
  try {
    a = DoubleArray::ensure(obj);
  } catch (const py::error_already_set&) {
    a = DoubleArray();
  }
  if (!a || a.ndim() != 2 || (a.shape(1) != 3 && a.shape(0) > 0))
    throw Error(Status::BadInput, "python", std::string(what) + " must be an N×3 array of numbers");
  std::vector<Vec3> out(static_cast<std::size_t>(a.shape(0)));
  auto r = a.unchecked<2>();
  for (py::ssize_t i = 0; i < a.shape(0); ++i) {
    out[static_cast<std::size_t>(i)] = Vec3(r(i, 0), r(i, 1), r(i, 2));
    if (!out[static_cast<std::size_t>(i)].allFinite())
      throw Error(Status::BadInput, "python", std::string(what) + " row " + std::to_string(i) + " is not finite");
  }
  return out;
}

/// numpy points (+ optional normals) → PointCloud in local coordinates.
std::shared_ptr<PointCloud> to_cloud(const py::handle& points, const py::handle& normals) {
  auto cloud = std::make_shared<PointCloud>();
  cloud->points = to_vec3s(points, "points");
  cloud->source = "<numpy>";
  if (!normals.is_none()) {
    cloud->normals = to_vec3s(normals, "normals");
    if (cloud->normals.size() != cloud->points.size())
      throw Error(Status::BadInput, "python", "normals has " + std::to_string(cloud->normals.size()) +
                                                  " rows, points " + std::to_string(cloud->points.size()));
    for (std::size_t i = 0; i < cloud->normals.size(); ++i) {
      const double len = cloud->normals[i].norm();
      if (!(len > 0)) throw Error(Status::BadInput, "python", "normal " + std::to_string(i) + " has zero length");
      cloud->normals[i] /= len;
    }
  }
  // Large (georeferenced) coordinates: shifted to a local origin as the file readers shift them (io.h).
  cloud->origin = local_origin(cloud->points);
  if (cloud->origin != Vec3::Zero())
    for (Vec3& p : cloud->points) p -= cloud->origin;
  return cloud;
}

std::vector<Vec3> global(std::vector<Vec3> v, const Vec3& origin) {
  for (Vec3& p : v) p += origin;
  return v;
}

py::list faces_to_py(const std::vector<std::vector<std::uint32_t>>& faces) {
  py::list out;
  for (const auto& f : faces) out.append(to_numpy_1d(std::vector<std::int64_t>(f.begin(), f.end())));
  return out;
}

/// vertices (N×3) + faces (sequence of index sequences) → PolygonMesh in the frame of `origin`.
PolygonMesh to_mesh(const py::handle& vertices, const py::handle& faces, const Vec3& origin = Vec3::Zero()) {
  PolygonMesh m;
  m.vertices = to_vec3s(vertices, "vertices");
  for (Vec3& v : m.vertices) v -= origin;
  m.origin = origin;
  std::size_t k = 0;
  for (const py::handle f : faces) {
    std::vector<std::uint32_t> face;
    for (const py::handle i : f) {
      const long long idx = py::cast<long long>(i);
      if (idx < 0 || static_cast<std::size_t>(idx) >= m.vertices.size())
        throw Error(Status::BadInput, "python", "face " + std::to_string(k) + " has vertex index " +
                                                    std::to_string(idx) + " out of range");
      face.push_back(static_cast<std::uint32_t>(idx));
    }
    if (face.size() < 3) throw Error(Status::BadInput, "python", "face " + std::to_string(k) + " has fewer than 3 vertices");
    m.faces.push_back(std::move(face));
    ++k;
  }
  return m;
}

py::dict mesh_to_py(const PolygonMesh& m) {
  py::dict d;
  d["vertices"] = to_numpy(global(m.vertices, m.origin));
  d["faces"] = faces_to_py(m.faces);
  return d;
}

py::object json_to_py(const nlohmann::json& j) {
  return py::module_::import("json").attr("loads")(j.dump());
}

// --------------------------------------------------------------------------------------------- kwargs

/// Reads known keyword arguments; any key left over is an error naming it.
class Kwargs {
 public:
  explicit Kwargs(const py::kwargs& kw, std::string function) : function_(std::move(function)) {
    for (auto item : kw) items_[py::cast<std::string>(item.first)] = py::reinterpret_borrow<py::object>(item.second);
  }
  template <class T>
  void get(const std::string& key, T& value) {
    auto it = items_.find(key);
    if (it == items_.end()) return;
    try {
      value = py::cast<T>(it->second);
    } catch (const py::cast_error&) {
      throw py::type_error(function_ + "(): argument '" + key + "' has the wrong type");
    }
    items_.erase(it);
  }
  bool has(const std::string& key) const { return items_.count(key) > 0; }
  void done() const {
    if (!items_.empty()) throw py::type_error(function_ + "() got an unexpected keyword argument '" + items_.begin()->first + "'");
  }

 private:
  std::string function_;
  std::map<std::string, py::object> items_;
};

void read_structure_params(Kwargs& kw, StructureParams& p) {
  std::string detector;
  kw.get("detector", detector);
  if (detector == "ransac") p.detector = PlaneDetector::Ransac;
  else if (detector == "region-growing" || detector == "region_growing") p.detector = PlaneDetector::RegionGrowing;
  else if (!detector.empty())
    throw Error(Status::BadInput, "python", "unknown plane detector '" + detector + "' (region-growing | ransac)");
  kw.get("seed", p.seed);
  kw.get("spacing", p.spacing);
  kw.get("max_distance", p.max_distance);
  kw.get("max_angle_deg", p.max_angle_deg);
  kw.get("min_region_points", p.min_region_points);
  kw.get("regularize", p.regularize);
  kw.get("alpha_radius", p.alpha_radius);
  kw.get("min_region_fraction", p.min_region_fraction);
  kw.get("min_segment_points", p.min_segment_points);
  kw.get("segment_max_distance", p.segment_max_distance);
}

void read_partition_params(Kwargs& kw, PartitionParams& p) {
  std::string method;
  kw.get("partition", method);
  kw.get("method", method);
  if (!method.empty()) p.method = parse_partitioner(method);
  kw.get("bbox_margin", p.bbox_margin);
  kw.get("kinetic_k", p.kinetic_k);
}

void read_extraction_params(Kwargs& kw, ExtractionParams& p) {
  std::string detail;
  kw.get("detail", detail);
  if (!detail.empty()) apply_detail(parse_detail(detail), p);  // then lambda / face_price override it
  kw.get("face_price", p.face_price);
  kw.get("lambda", p.lambda);
  kw.get("lambda_", p.lambda);
}

// ------------------------------------------------------------------------------------ stage handles

/// Stage 1 result, with the cloud it was computed from (the next stages need both).
struct StructureHandle {
  std::shared_ptr<PointCloud> cloud;
  std::shared_ptr<SceneStructure> structure;
};

/// Stage 2 result; `cloud` has each inlier's normal flipped to its plane's outward side (as run_pipeline).
struct VisibilityHandle {
  StructureHandle s;
  std::shared_ptr<PointCloud> cloud;
  std::shared_ptr<VisibilityResult> visibility;
};

struct RecoveryHandle {
  VisibilityHandle v;
  std::shared_ptr<RecoveryResult> recovery;
};

struct PartitionHandle {
  VisibilityHandle v;
  std::vector<ConvexPolygon> polygons;
  std::shared_ptr<CellComplex> complex;
};

py::dict plane_to_py(const DetectedPlane& p, const Vec3& origin) {
  py::dict d;
  d["normal"] = vec3(p.plane.normal);
  d["offset"] = p.plane.offset - p.plane.normal.dot(origin);  // n·x + d = 0 in global coordinates
  d["inliers"] = to_numpy_1d(std::vector<int>(p.inliers));
  d["centroid"] = vec3(p.centroid + origin);
  d["area"] = p.area;
  std::vector<Vec3> seg;
  for (const auto& s : p.segments) {
    seg.push_back(s.a + origin);
    seg.push_back(s.b + origin);
  }
  d["segments"] = to_numpy(std::move(seg));  // 2k×3: segment k from row 2k to row 2k+1
  return d;
}

StructureHandle detect_planes(const py::object& points, const py::object& normals, const py::kwargs& kwargs) {
  Kwargs kw(kwargs, "detect_planes");
  StructureParams params;
  read_structure_params(kw, params);
  kw.done();
  StructureHandle h;
  h.cloud = to_cloud(points, normals);
  py::gil_scoped_release release;
  h.structure = std::make_shared<SceneStructure>(run_structure(*h.cloud, params));
  return h;
}

VisibilityHandle visibility(const StructureHandle& s, const py::kwargs& kwargs) {
  Kwargs kw(kwargs, "visibility");
  VisibilityParams params;
  kw.get("keypoints", params.keypoints);
  kw.get("directions", params.directions);
  kw.get("smoothness", params.smoothness);
  kw.done();
  VisibilityHandle h;
  h.s = s;
  {
    py::gil_scoped_release release;
    h.visibility = std::make_shared<VisibilityResult>(run_visibility(*s.cloud, *s.structure, params));
    h.cloud = std::make_shared<PointCloud>(*s.cloud);
    h.cloud->normals = s.structure->normals;
    orient_inlier_normals(*s.structure, *h.visibility, h.cloud->normals);
  }
  return h;
}

RecoveryHandle recover_planes(const VisibilityHandle& v, const py::kwargs& kwargs) {
  Kwargs kw(kwargs, "recover_planes");
  RecoveryParams params;
  kw.get("angle_deg", params.angle_deg);
  kw.get("distance", params.distance);
  kw.get("min_segments", params.min_segments);
  kw.get("split_regions", params.split_regions);
  kw.get("level_caps", params.level_caps);
  kw.done();
  RecoveryHandle h;
  h.v = v;
  py::gil_scoped_release release;
  h.recovery = std::make_shared<RecoveryResult>(run_recovery(*v.cloud, *v.s.structure, params));
  return h;
}

PartitionHandle partition(const RecoveryHandle& r, const py::kwargs& kwargs) {
  Kwargs kw(kwargs, "partition");
  PartitionParams params;
  read_partition_params(kw, params);
  HullsParams hp;
  kw.get("recovery", hp.recovered_planes);
  kw.done();
  PartitionHandle h;
  h.v = r.v;
  py::gil_scoped_release release;
  h.polygons = run_hulls(*r.v.cloud, *r.v.s.structure, *r.v.visibility, *r.recovery, hp);
  PartitionInput in;
  in.polygons = h.polygons;
  in.points_bbox = bounding_box(r.v.cloud->points);
  in.adjacent_planes = polygon_adjacency(*r.v.s.structure, *r.recovery);
  h.complex = std::make_shared<CellComplex>(run_partition(in, params));
  return h;
}

py::dict extract(const PartitionHandle& p, const py::kwargs& kwargs) {
  Kwargs kw(kwargs, "extract");
  ExtractionParams params;
  read_extraction_params(kw, params);
  kw.done();
  ExtractionInput in;
  in.complex = p.complex.get();
  in.cloud = p.v.cloud.get();
  in.point_plane = &p.v.s.structure->point_plane;
  in.spacing = p.v.s.structure->spacing;
  ExtractionResult r;
  {
    py::gil_scoped_release release;
    r = run_extraction(in, params);
  }
  r.mesh.origin = p.v.cloud->origin;
  py::dict d = mesh_to_py(r.mesh);
  d["inside"] = py::cast(std::vector<bool>(r.inside));
  d["energy"] = r.energy;
  return d;
}

py::dict reconstruct(const py::object& points, const py::object& normals, const py::kwargs& kwargs) {
  Kwargs kw(kwargs, "reconstruct");
  PipelineParams params;
  // What the user chose (scene/plan.h UserChoices: a scene kind's defaults never override it), read before
  // the keys are taken.
  for (const char* key : {"detail", "face_price", "lambda", "lambda_"}) params.user.detail = params.user.detail || kw.has(key);
  params.user.min_plane_share = kw.has("min_region_fraction");
  params.user.min_plane_points = kw.has("min_region_points");
  read_structure_params(kw, params.structure);
  read_partition_params(kw, params.partition);
  read_extraction_params(kw, params.extraction);
  kw.get("recovery", params.hulls.recovered_planes);
  std::string scene;
  kw.get("scene", scene);
  if (!scene.empty()) params.scene.mode = parse_scene_mode(scene);
  kw.get("ground_z", params.scene.building.ground_z);  // global coordinates; made local below
  kw.get("wall_weight", params.extraction.wall_area_weight);
  kw.get("force", params.force);
  kw.get("mesh_samples", params.eval.mesh_samples);
  std::string html;
  kw.get("html", html);
  py::object truth = py::none();
  if (kw.has("truth")) kw.get("truth", truth);
  kw.done();
  const auto cloud = to_cloud(points, normals);
  params_to_local(params, cloud->origin);
  PolygonMesh truth_mesh;
  if (!truth.is_none()) {
    truth_mesh = to_mesh(truth[py::str("vertices")], truth[py::str("faces")], cloud->origin);
    params.truth = &truth_mesh;
  }
  PipelineArtifacts artifacts;
  if (!html.empty()) params.artifacts = &artifacts;
  PipelineResult result;
  {
    py::gil_scoped_release release;
    result = run_pipeline(*cloud, params);
    if (!html.empty()) write_html_report(html, artifacts, result.mesh, result.report);
  }
  py::dict d = mesh_to_py(result.mesh);
  py::list classes;
  for (FaceClass c : result.mesh.face_class) classes.append(face_class_name(c));
  d["face_class"] = classes;
  d["report"] = json_to_py(result.report);
  d["valid"] = result.eval.validity.valid();
  return d;
}

py::dict cloud_to_py(const PointCloud& c) {
  py::dict d;
  d["points"] = to_numpy(global(c.points, c.origin));
  d["normals"] = c.has_normals() ? py::object(to_numpy(std::vector<Vec3>(c.normals))) : py::object(py::none());
  return d;
}

}  // namespace

// The compiled part of the package `hsr` (python/hsr/__init__.py re-exports it).
PYBIND11_MODULE(_hsr, m) {
  m.doc() = "hsr: watertight polygonal surface reconstruction of man-made scenes from point clouds "
            "(Hierarchical Space Partition). numpy in, numpy out.";
  m.attr("__version__") = HSR_VERSION;
  log::set_level(log::Level::Quiet);

  static py::exception<Error> error_type(m, "Error", PyExc_RuntimeError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const Error& e) {
      py::object type = py::reinterpret_borrow<py::object>(error_type);
      py::object err = type(e.one_line());
      err.attr("status") = status_name(e.status());
      err.attr("stage") = e.stage();
      PyErr_SetObject(error_type.ptr(), err.ptr());
    }
  });

  m.def("set_verbosity", [](const std::string& level) {
    if (level == "quiet") log::set_level(log::Level::Quiet);
    else if (level == "info") log::set_level(log::Level::Info);
    else if (level == "verbose") log::set_level(log::Level::Verbose);
    else throw py::value_error("verbosity is 'quiet', 'info' or 'verbose'");
  }, py::arg("level"), "Log level of the stages (stderr): 'quiet' (default), 'info', 'verbose'.");

  // --- I/O
  m.def("read_points", [](const std::string& path, std::size_t sample, std::uint64_t seed) {
    ReadParams rp;
    rp.sample_count = sample;
    rp.seed = seed;
    return cloud_to_py(read_points(path, rp));
  }, py::arg("path"), py::arg("sample") = 0, py::arg("seed") = 1,
  "Reads a point file (.ply .xyz .xyzn .pwn .off .las; meshes: their vertices, or `sample` points on the faces).\n"
  "Returns {'points': N×3, 'normals': N×3 or None} in the file's coordinates.");
  m.def("read_mesh", [](const std::string& path) { return mesh_to_py(read_mesh(path)); }, py::arg("path"),
        "Reads a polygon mesh (.obj .ply .off .city.json). Returns {'vertices': N×3, 'faces': [int arrays]}.");
  m.def("write_mesh", [](const std::string& path, const py::object& vertices, const py::object& faces) {
    write_mesh(path, to_mesh(vertices, faces));
  }, py::arg("path"), py::arg("vertices"), py::arg("faces"),
  "Writes a polygon mesh (.obj .ply .off .city.json, by extension), atomically.");

  // --- whole pipeline
  m.def("reconstruct", &reconstruct, py::arg("points"), py::arg("normals") = py::none(),
        "Reconstructs a watertight polygon mesh from N×3 points (and optional N×3 normals).\n"
        "Keyword parameters: scene='auto'|'building'|'object' (building: aerial scan, up +z, ground, walls),\n"
        "ground_z (building: ground height when none is detected), wall_weight=0.25,\n"
        "partition='hierarchical'|'bsp'|'exhaustive'|'kinetic', detail='full'|'high'|'medium'|'low' (default\n"
        "medium), lambda_=0.5 (or 'lambda'), face_price (label clean-up; default by detail),\n"
        "detector='region-growing'|'ransac', seed, bbox_margin, recovery=True, force=False, mesh_samples,\n"
        "truth={'vertices','faces'} (adds accuracy against it), html='report.html' (writes the visual report).\n"
        "Returns {'vertices': V×3, 'faces': [int arrays], 'face_class': ['roof'|'wall'|'ground'|'closure'...],\n"
        "'report': dict, 'valid': bool}.\n"
        "Raises hsr.Error('stage: problem') on failure (e.g. invalid output unless force=True).");

  // --- stages one by one
  py::class_<StructureHandle>(m, "Structure", "Stage 1 (detect_planes) result.")
      .def_property_readonly("spacing", [](const StructureHandle& h) { return h.structure->spacing; },
                             "average point spacing r (absolute)")
      .def_property_readonly("normals", [](const StructureHandle& h) {
        return to_numpy(std::vector<Vec3>(h.structure->normals));
      }, "N×3 unit normals (the input's, or estimated and oriented)")
      .def_property_readonly("point_plane", [](const StructureHandle& h) {
        return to_numpy_1d(std::vector<int>(h.structure->point_plane));
      }, "per point: plane index, -1 for none")
      .def_property_readonly("planes", [](const StructureHandle& h) {
        py::list l;
        for (const auto& p : h.structure->planes) l.append(plane_to_py(p, h.cloud->origin));
        return l;
      }, "list of dicts: normal, offset (n·x + offset = 0), inliers, centroid, area, segments (2k×3)")
      .def_property_readonly("adjacency", [](const StructureHandle& h) { return h.structure->adjacency; })
      .def_property_readonly("params", [](const StructureHandle& h) { return json_to_py(h.structure->params); })
      .def("__len__", [](const StructureHandle& h) { return h.structure->planes.size(); })
      .def("__repr__", [](const StructureHandle& h) {
        return "<hsr.Structure: " + std::to_string(h.structure->planes.size()) + " planes>";
      });
  m.def("detect_planes", &detect_planes, py::arg("points"), py::arg("normals") = py::none(),
        "Stage 1 (paper §3.1): normals, planes, boundaries, adjacency. Keywords: detector, seed, spacing,\n"
        "max_distance (in r), max_angle_deg, min_region_points, min_region_fraction, regularize, alpha_radius (in r),\n"
        "min_segment_points, segment_max_distance (in r).");

  py::class_<VisibilityHandle>(m, "Visibility", "Stage 2 (visibility) result.")
      .def_property_readonly("ratio", [](const VisibilityHandle& h) {
        return to_numpy_1d(std::vector<double>(h.visibility->ratio));
      }, "per plane: fraction of visible rays")
      .def_property_readonly("outward_normal", [](const VisibilityHandle& h) {
        return to_numpy(std::vector<Vec3>(h.visibility->outward_normal));
      })
      .def_property_readonly("highly", [](const VisibilityHandle& h) { return std::vector<bool>(h.visibility->highly); },
                             "per plane: True highly visible (level 1), False barely (level 2)")
      .def_property_readonly("normals", [](const VisibilityHandle& h) {
        return to_numpy(std::vector<Vec3>(h.cloud->normals));
      }, "N×3 normals, each inlier's flipped to its plane's outward side");
  m.def("visibility", &visibility, py::arg("structure"),
        "Stage 2 (paper §3.2): visibility ratio, outward normal and level per plane. Keywords: keypoints,\n"
        "directions, smoothness.");

  py::class_<RecoveryHandle>(m, "Recovery", "Stage 3 (recover_planes) result.")
      .def_property_readonly("recovered", [](const RecoveryHandle& h) {
        py::list l;
        const Vec3& o = h.v.cloud->origin;
        for (const auto& r : h.recovery->recovered) {
          py::dict d;
          d["normal"] = vec3(r.plane.normal);
          d["offset"] = r.plane.offset - r.plane.normal.dot(o);
          d["support"] = to_numpy_1d(std::vector<int>(r.support));
          py::list segs;
          for (const auto& s : r.segments) segs.append(py::make_tuple(s.plane, s.segment));
          d["segments"] = segs;
          l.append(d);
        }
        return l;
      }, "list of dicts: normal, offset, support (point indices), segments [(plane, segment)]")
      .def_property_readonly("singular", [](const RecoveryHandle& h) { return h.recovery->singular; },
                             "per plane, per boundary segment: True when singular")
      .def_property_readonly("num_singular", [](const RecoveryHandle& h) { return h.recovery->num_singular(); });
  m.def("recover_planes", &recover_planes, py::arg("visibility"),
        "Stage 3 (paper §3.3): singular segments and recovered (missing) planes. Keywords: angle_deg,\n"
        "distance (in r), min_segments, split_regions and level_caps (a room's recovery, DECISIONS #66; off here, on "
        "in hsr reconstruct for a room).");

  py::class_<PartitionHandle>(m, "Partition", "Stages 4–5 (hulls, partition) result: the cell complex.")
      .def_property_readonly("polygons", [](const PartitionHandle& h) {
        py::list l;
        for (const auto& p : h.polygons) {
          py::dict d;
          d["plane_id"] = p.plane_id;
          d["level"] = p.level;
          d["speed"] = p.speed;
          d["vertices"] = to_numpy(global(p.vertices, h.v.cloud->origin));
          l.append(d);
        }
        return l;
      }, "the convex polygons handed to the partition: plane_id, level, speed, vertices")
      .def_property_readonly("vertices", [](const PartitionHandle& h) {
        return to_numpy(global(h.complex->vertices_approx, h.v.cloud->origin));
      }, "complex vertices (doubles)")
      .def_property_readonly("facets", [](const PartitionHandle& h) {
        py::list l;
        for (const auto& f : h.complex->facets) l.append(to_numpy_1d(std::vector<std::int64_t>(f.vertices.begin(), f.vertices.end())));
        return l;
      }, "per facet: its vertex loop")
      .def_property_readonly("facet_cells", [](const PartitionHandle& h) {
        std::vector<int> c;
        for (const auto& f : h.complex->facets) c.insert(c.end(), f.cells.begin(), f.cells.end());
        auto a = to_numpy_1d(std::move(c));
        return a.reshape({static_cast<py::ssize_t>(h.complex->facets.size()), py::ssize_t{2}});
      }, "F×2: cell on the positive / negative side of each facet (-1: outside the box)")
      .def_property_readonly("cells", [](const PartitionHandle& h) {
        py::list l;
        for (const auto& c : h.complex->cells) l.append(to_numpy_1d(std::vector<std::int64_t>(c.facets.begin(), c.facets.end())));
        return l;
      }, "per cell: its facet indices")
      .def_property_readonly("volumes", [](const PartitionHandle& h) {
        std::vector<double> v;
        for (const auto& c : h.complex->cells) v.push_back(c.volume_approx);
        return to_numpy_1d(std::move(v));
      })
      .def("validate", [](const PartitionHandle& h) { return validate(*h.complex, &h.polygons).problems; },
           "Checks the complex's invariants exactly; returns the list of problems (empty: valid).")
      .def("__repr__", [](const PartitionHandle& h) {
        return "<hsr.Partition: " + std::to_string(h.complex->cells.size()) + " cells>";
      });
  m.def("partition", &partition, py::arg("recovery"),
        "Stages 4–5 (paper §3.4–3.5): convex polygons with levels and speeds, then the space partition.\n"
        "Keywords: method (or partition)='hierarchical'|'bsp'|'exhaustive'|'kinetic', bbox_margin, kinetic_k,\n"
        "recovery=True (use recovered planes).");
  m.def("extract", &extract, py::arg("partition"),
        "Stage 6 (paper §3.6): inside/outside labels by min-cut and the output mesh. Keyword: lambda_.\n"
        "Returns {'vertices', 'faces', 'inside' (per cell), 'energy'}.");

  // --- evaluation and helpers
  m.def("evaluate", [](const py::object& points, const py::object& vertices, const py::object& faces,
                       const py::object& truth, std::size_t samples) {
    const auto cloud = to_cloud(points, py::none());
    const PolygonMesh mesh = to_mesh(vertices, faces, cloud->origin);
    PolygonMesh truth_mesh;
    if (!truth.is_none()) truth_mesh = to_mesh(truth[py::str("vertices")], truth[py::str("faces")], cloud->origin);
    EvalParams ep;
    ep.samples_per_point = 0;  // hsr.evaluate is the full evaluation (mesh_samples on every mesh)
    ep.mesh_samples = samples;
    EvalResult r;
    {
      py::gil_scoped_release release;
      r = run_eval(*cloud, mesh, truth.is_none() ? nullptr : &truth_mesh, ep);
    }
    py::dict d = py::cast<py::dict>(json_to_py(to_json(r)));
    d["valid"] = r.validity.valid();
    return d;
  }, py::arg("points"), py::arg("vertices"), py::arg("faces"), py::arg("truth") = py::none(),
  py::arg("samples") = 200000,
  "Accuracy (distances as fractions of the bbox diagonal) and validity of a mesh against points (and an\n"
  "optional true mesh {'vertices','faces'}). Returns the report dict plus 'valid'.");

  m.def("synth", [](const std::string& model, std::uint64_t seed, double noise, std::size_t points, double density,
                    int blocks, int planes) {
    SynthParams sp;
    sp.seed = seed;
    if (noise >= 0) sp.noise = noise;
    if (points > 0) sp.target_points = points;
    sp.density = density;
    sp.blocks = blocks;
    sp.planes = planes;
    SynthScan s = run_synth(model, sp);
    py::dict d = cloud_to_py(s.cloud);
    PolygonMesh truth = s.truth;
    truth.origin = s.cloud.origin;
    d["truth"] = mesh_to_py(truth);
    return d;
  }, py::arg("model"), py::arg("seed") = 1, py::arg("noise") = -1.0, py::arg("points") = 0, py::arg("density") = 0.0,
  py::arg("blocks") = 0, py::arg("planes") = 0,
  "Simulated LiDAR scan of a procedural model: {'points', 'normals', 'truth': {'vertices','faces'}}.\n"
  "The aerial_* models (hsr.synth_aerial_models()) are scanned from the air; their seed draws the building.\n"
  "The indoor models (hsr.synth_indoor_models(): hall, meeting_room, office) take density (points per m²; 0: their\n"
  "own), blocks (hall: furniture pieces, meeting_room: chairs) and planes (hall: about this many planes).");
  m.def("synth_models", &synth_model_names, "Names of the terrestrial synth models.");
  m.def("synth_aerial_models", &synth_aerial_model_names, "Names of the aerial building synth models.");
  m.def("synth_indoor_models", &synth_indoor_model_names, "Names of the indoor synth models (scanned from inside).");
  bind_driver(m);

  m.def("triangulate", [](const py::object& vertices, const py::object& faces) {
    const PolygonMesh mesh = to_mesh(vertices, faces);
    std::vector<std::int64_t> t;
    for (const auto& tri : triangulate_faces(mesh)) t.insert(t.end(), tri.begin(), tri.end());
    const auto rows = static_cast<py::ssize_t>(t.size() / 3);
    return to_numpy_1d(std::move(t)).reshape({rows, py::ssize_t{3}});
  }, py::arg("vertices"), py::arg("faces"), "Triangles (T×3 indices) covering each polygon face (e.g. for Open3D).");
}
