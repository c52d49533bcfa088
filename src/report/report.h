// Visual reports (DESIGN.md §1 "pipeline"; issue "Python module and visual reports of every stage").
//
// write_html_report(): one self-contained HTML page (works offline: three.js r111 from Debian's libjs-three
// and its OrbitControls are inlined at build time, no external URL is loaded) with one interactive 3D view
// per stage of a run: the input points; the detected planes (inliers coloured by plane, boundary segments);
// the visibility ratio; the levels (highly / barely visible, recovered planes' support); the convex polygons
// handed to the partition (coloured by level); the partition (cells exploded away from the box centre,
// inside cells solid); the output mesh over the points coloured by point-to-mesh distance; and the run
// report (parameters, timings, counts, validity, accuracy) as tables.
// html_still() is the same page with a single view filling the window (a mesh and/or points), which
// render_png() loads in headless Chromium to take a screenshot (`hsr render`, `hsr reconstruct --png`).
//
// Page size: every points layer shows at most ReportParams::max_points points (an evenly strided,
// deterministic subsample shared by all views); geometry is stored as base64 float32 in one JSON block.
// When the page has rendered a view it marks the view's element data-rendered="1" and
// data-nonbackground="<pixels differing from the background>", and when all are done sets document.title to
// "hsr: rendered K/N views, E errors" (script errors and console.error calls are listed in #hsr-errors).
// Tests and render_png() read these marks.
// Faces are triangulated and point-to-mesh distances measured by eval's routines (eval/eval.h:
// triangulate_polygon, point_mesh_distances), the ones the validity checks and accuracy figures use.
//
// Indoor view (issue 25, README "Indoor scenes"): a model scanned from inside is a room's air, a closed box
// whose outside shows nothing of the room. The cutaway view looks at it from above with its top cut away:
// nothing above a horizontal cut just under the top is drawn (points, polygons, cells, the mesh: the
// ceiling goes), and a closed, outward-oriented mesh is drawn from its inner side only, so the walls nearest
// the camera vanish from every viewpoint while the floor, the furniture and the far walls stay. It is chosen
// automatically for a model scanned from inside (ReportParams::scanned_from_inside: the visibility stage's
// finding in a run, normals_face_inward() for files) or by ReportParams::view; the report page has a
// checkbox to switch it off and on.
#pragma once

#include "core/types.h"
#include "pipeline/pipeline.h"

#include <nlohmann/json.hpp>

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace hsr {

/// How the model is shown: Outside (the whole model from outside), Cutaway (from above, the top cut away,
/// a closed mesh from its inner side: see the file comment), Auto (Cutaway when scanned from inside).
enum class ModelView { Auto, Outside, Cutaway };

/// "auto" | "outside" | "cutaway" (the CLI's --view); throws Error(BadInput, "render") otherwise.
ModelView parse_model_view(const std::string& name);

struct ReportParams {
  std::size_t max_points = 50000;  ///< points shown per view, at most (deterministic strided subsample)
  double explode = 0.6;            ///< partition view: a cell moves by this fraction of its centroid's offset from the box centre
  double point_size = 2.0;         ///< points, in CSS pixels
  std::string title;               ///< page title (default: the input file name from the run report)
  /// html_still: canvas size in CSS pixels (0: the window's). Set it to the screenshot size: headless
  /// Chromium's viewport can be smaller than its --window-size, which would leave the still off-centre.
  int still_width = 0, still_height = 0;
  ModelView view = ModelView::Auto;  ///< see ModelView
  bool scanned_from_inside = false;  ///< the model was scanned from inside: Auto shows the cutaway
  /// Cutaway: the cut lies this fraction of the model's height (z extent of points and mesh) below its top.
  double cut_depth = 0.1;
};

/// Whether a page made with these parameters shows the cutaway view.
bool cutaway_view(const ReportParams& params);


/// The report page of one run as a string. `artifacts` as filled by run_pipeline; `mesh` its output
/// (local coordinates, like the artifacts); `run_report` PipelineResult::report.
std::string html_report(const PipelineArtifacts& artifacts, const PolygonMesh& mesh, const nlohmann::json& run_report,
                        const ReportParams& params = {});
/// Writes html_report() to `path` (atomically). Throws hsr::Error(stage "report") on I/O failure.
void write_html_report(const std::string& path, const PipelineArtifacts& artifacts, const PolygonMesh& mesh,
                       const nlohmann::json& run_report, const ReportParams& params = {});

/// A page with one view filling the window: `mesh` (may be null or empty; faces light grey, edges dark)
/// over `points` (may be null or empty; coloured by distance to the mesh when there is one, else by
/// height). Both in the same coordinates. Throws Error(BadInput) when both are empty.
std::string html_still(const PolygonMesh* mesh, const PointCloud* points, const ReportParams& params = {});

struct RenderParams {
  int width = 1200, height = 900;  ///< screenshot size, pixels
  std::string chromium;            ///< browser executable; empty: $HSR_CHROMIUM, else chromium / chromium-browser on PATH
  int timeout_seconds = 180;       ///< the browser is killed after this
  int virtual_time_ms = 20000;     ///< --virtual-time-budget: page time allowed for WebGL to draw
  /// Let the page read the files beside it (file:// fetches; the 3D Tiles viewer loads tileset.json and its
  /// contents): Chromium's --allow-file-access-from-files.
  bool allow_file_access = false;
};

/// The Chromium executable render_png() would use, or "" when none is installed.
std::string find_chromium(const RenderParams& params = {});

/// Loads the page `html_path` in headless Chromium and saves a PNG screenshot (atomically: written to a temp
/// folder, then moved). Throws hsr::Error(stage "render"): NotImplemented when Chromium is not installed
/// (naming the Debian package), Internal when the browser fails or writes no image.
void render_png(const std::string& html_path, const std::string& png_path, const RenderParams& params = {});

}  // namespace hsr
