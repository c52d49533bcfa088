// CityJSON 2.0 output (README "City scale"; spec https://www.cityjson.org/specs/2.0.1/): one `Building` per
// mesh with an LoD 2.2 `Solid` (one exterior shell; each face one surface with its exterior ring; our meshes
// have no holes, so no inner rings are written), `semantics` RoofSurface / WallSurface / GroundSurface /
// ClosureSurface from core/face_class.h (`face_classes_or_by_normal`: the building mode's classes where set,
// else by normal), integer vertices with a `transform`, and the run's figures as attributes. CityJSONSeq
// (`.city.jsonl`): a CityJSON header line with the transform and metadata, then one CityJSONFeature per line.
// A reader of what this writer produces (round trips, `hsr eval`, the batch's sequence).
//
// Integers. Vertex v (local) of a mesh with origin o is written as q = round((v + o - translate) / scale); the
// translate is the mesh's origin (io.h: an integer-valued shift for georeferenced data, else 0), so a decoded
// coordinate q·scale + translate lies within scale/2 of the global one. Rounding can merge vertices and
// flatten faces; `quantize_solid` then dedupes vertices (first appearance order), drops repeated
// consecutive ring vertices, splits a ring that touches itself at a merged vertex, drops rings of zero
// area (inserting the vertices of a ring flattened to a segment into the neighbouring edges they now lie
// on, so no T-junction is left), and verifies the result: every ring >= 3 distinct in-range vertices with a
// non-zero (exact) area; with `require_valid`, every edge used once in each direction (closed, oriented,
// 2-manifold at its edges) and, when CityJsonParams::validate is set (the CLI and `hsr batch` set it to
// eval's check_validity; io itself stays free of CGAL), the decoded solid valid. A document whose solid
// fails is tried again on grids ten times finer (CityJsonParams::finer_steps; a warning names the scale
// used, which its transform holds): a building is not lost to rounding. When every step fails,
// Error(InvalidOutput, "io") names the failed check; nothing is written. A CityJSONFeature is rounded at
// the sequence header's scale only.
// All writes are atomic (core/atomic_file.h); same mesh and parameters, same bytes.
#pragma once

#include "core/types.h"

#include <nlohmann/json.hpp>

#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace hsr {

struct CityJsonParams {
  /// Size of one integer step of the vertex coordinates, in the mesh's units (metres for georeferenced
  /// data): `transform.scale` on x, y and z. Must be > 0. Default 1 mm.
  double scale = 0.001;
  /// Coordinate reference system "EPSG:NNNN", written as `metadata.referenceSystem` (the OGC URL
  /// https://www.opengis.net/def/crs/EPSG/0/NNNN). Empty: no reference system is written.
  std::string crs;
  /// Id of the Building city object (and of its CityJSONFeature). Empty: "building".
  std::string id;
  /// The Building's `attributes` (a JSON object), e.g. cityjson_attributes(run report).
  nlohmann::json attributes = nlohmann::json::object();
  /// Refuse (InvalidOutput) a solid that is not valid after rounding. Off for --force runs, whose mesh may
  /// be invalid to begin with (it is then written as rounded, rings still cleaned).
  bool require_valid = true;
  /// With require_valid: the full check of the decoded solid, "" when valid, else what fails (e.g. eval's
  /// check_validity summary). Empty function: only the rings and the edge pairing are checked.
  std::function<std::string(const PolygonMesh&)> validate;
  /// A document (not a feature) whose rounded solid fails a check is rounded again at scale / 10, / 100, ...
  /// up to this many times. 0: exactly `scale` or InvalidOutput.
  int finer_steps = 3;
  /// Attributes of one surface of a written solid (its LoD, the rounded solid decoded, the face's index):
  /// a JSON object gives that face a Semantic Object of its own ({"type": its class, ...the attributes}),
  /// null (or an empty function) leaves it in the one Semantic Object of its class. `hsr city` gives each
  /// LoD 2.2 RoofSurface its slope, azimuth and area (src/city/lods.h roof_surface_attributes).
  std::function<nlohmann::json(const std::string& lod, const PolygonMesh& solid, std::size_t face)> surface_attributes;
};

/// One geometry of a Building: a solid and its LoD ("1.2", "1.3", "2.2").
struct CityJsonGeometry {
  std::string lod = "2.2";
  PolygonMesh mesh;
};

/// True for a path ending in ".city.json" (case-insensitive).
bool is_cityjson_path(const std::string& path);
/// True for a path ending in ".city.jsonl" (case-insensitive).
bool is_cityjsonseq_path(const std::string& path);

/// "EPSG:NNNN" (case-insensitive prefix, NNNN digits) -> "https://www.opengis.net/def/crs/EPSG/0/NNNN".
/// Throws Error(BadInput, "io") for anything else.
std::string crs_url(const std::string& crs);

/// The per-building attributes from a pipeline run report (pipeline.h): hsr_valid (bool), hsr_validity
/// ("valid" or the failed checks), hsr_p2m_mean and hsr_p2m_rms (mean and RMS distance from the input
/// points to the mesh, fractions of the points' bbox diagonal), hsr_facets (output faces), hsr_seconds
/// (pipeline wall time, s), hsr_version, and from the report's `quality` (issue 42): hsr_points_unexplained_share
/// (the share of the points to explain farther than 3 r from the model), hsr_scene, hsr_scene_choice ("auto" or
/// "given"), hsr_scene_margin, hsr_ground_source, hsr_removed_points ({rule: points}), hsr_fallback ("outline
/// prism" when detection found no plane, DECISIONS #135). Keys missing from the report are left out.
nlohmann::json cityjson_attributes(const nlohmann::json& report);

/// One building's geometry as written: integer vertices relative to `translate`, faces (exterior rings,
/// counter-clockwise seen from outside) and their classes, and what the rounding changed.
struct CityJsonSolid {
  double scale = 0.001;
  Vec3 translate = Vec3::Zero();
  std::vector<std::array<std::int64_t, 3>> vertices;
  std::vector<std::vector<std::uint32_t>> faces;
  std::vector<FaceClass> classes;  ///< one per face
  std::size_t merged_vertices = 0;  ///< input vertices that landed on an earlier vertex's integer point
  std::size_t dropped_faces = 0;    ///< faces (or pieces) with < 3 distinct vertices or zero area after rounding
  std::size_t split_faces = 0;      ///< faces whose ring touched itself after rounding, split into pieces
  /// vertices of faces flattened to a segment, inserted into the neighbouring edges they now lie on
  std::size_t inserted_vertices = 0;
};

/// Rounds `mesh` (global coordinates: vertices + origin) to the integer grid of `scale` around `translate`,
/// repairs and verifies it (see the header comment). Throws Error(BadInput, "io") for scale <= 0, non-finite
/// or out-of-range coordinates (|q| >= 2^53) and bad face indices; Error(InvalidOutput, "io") when
/// `require_valid` and the rounded solid fails a check (`validate` as CityJsonParams::validate).
CityJsonSolid quantize_solid(const PolygonMesh& mesh, double scale, const Vec3& translate, bool require_valid = true,
                             const std::function<std::string(const PolygonMesh&)>& validate = {});

/// The solid decoded back to doubles: vertices q·scale (local), origin = translate, face_class = classes.
PolygonMesh decode_solid(const CityJsonSolid& solid);

/// A whole CityJSON object holding one Building (translate = mesh.origin).
nlohmann::json cityjson_document(const PolygonMesh& mesh, const CityJsonParams& params);
/// Writes cityjson_document() to `path` (one line of compact JSON and a newline), atomically.
void write_cityjson(const std::string& path, const PolygonMesh& mesh, const CityJsonParams& params);

/// CityJSONSeq first line: a CityJSON object with the shared transform (params.scale, `translate`),
/// metadata (reference system; geographicalExtent when `extent` has 6 numbers) and no city objects.
nlohmann::json cityjson_seq_header(const CityJsonParams& params, const Vec3& translate,
                                   const std::vector<double>& extent = {});
/// A CityJSONFeature with the mesh as one Building, its integers relative to the header's `translate`, at
/// params.scale (the header's; no finer step).
nlohmann::json cityjson_feature(const PolygonMesh& mesh, const CityJsonParams& params, const Vec3& translate);
/// A CityJSONFeature whose Building has several solids, in the order given (`geometry` in that order; the
/// vertices of the first solid first, so its rings index as in the one-solid feature). Each solid is rounded
/// and checked as cityjson_feature's; the extent covers them all.
nlohmann::json cityjson_feature(const std::vector<CityJsonGeometry>& solids, const CityJsonParams& params, const Vec3& translate);
/// Writes a CityJSONSeq: the header, then each feature, one compact JSON object per line. Atomic.
void write_cityjsonseq(const std::string& path, const nlohmann::json& header, const std::vector<nlohmann::json>& features);

/// One Building read back: its mesh (vertices decoded, local to origin = the transform's translate;
/// face_class from its semantics, Unknown for null), id and attributes. With several Solids: `mesh` is the
/// one of the highest LoD (the first of them), `lods` holds each Solid with its LoD in file order.
struct CityBuilding {
  std::string id;
  PolygonMesh mesh;
  std::vector<CityJsonGeometry> lods;
  nlohmann::json attributes = nlohmann::json::object();
  std::vector<double> extent;  ///< the Building's geographicalExtent (6 numbers), or empty
};

struct CityModel {
  double scale = 0;
  Vec3 translate = Vec3::Zero();
  std::string reference_system;  ///< metadata.referenceSystem, or ""
  std::vector<CityBuilding> buildings;  ///< in file order (object key order for .city.json)
};

/// Reads a .city.json or .city.jsonl holding Building objects with one Solid each, as this writer makes
/// them (a solid's exterior shell only; a surface with inner rings is rejected). Throws Error(BadFormat,
/// "io") naming the rule broken (missing member, non-integer vertex, index out of range, semantics value
/// not indexing `surfaces`, ...), FileNotFound when the file is missing.
CityModel read_cityjson(const std::string& path);

}  // namespace hsr
