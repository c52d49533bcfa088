// A city for the browser (issue 40 item 4; README "City scale"): CityJSONSeq in, 3D Tiles 1.1 out, the way
// 3DBAG serves its models, with a page that shows it.
//
// write_3d_tiles() reads the sequences `hsr city` wrote (io/cityjson.h read_cityjson) and writes into a folder:
// - NAME.glb per sequence (glb.h): one node per building, named by its id, its attributes as the node's extras;
//   its faces triangulated (eval.h triangulate_polygon), flat shaded, coloured by surface (roof, wall, ground).
// - tileset.json (3D Tiles 1.1): a root tile without content, refine ADD, with one child per sequence whose
//   content is its glb (glTF content is 3D Tiles 1.1's own; no b3dm). Bounding volumes are boxes in the root's
//   frame; a leaf's geometricError is 0, the root's the diagonal of all.
//   Placement: when the sequences' CRS (or Tiles3dParams::crs) is known, the root's frame is east-north-up at the
//   centre of the survey and root.transform takes it to earth-centred, earth-fixed coordinates (EPSG:4978,
//   through GDAL/PROJ), so a globe client (CesiumJS) puts the city where it is. Heights are taken as the CRS
//   gives them (no geoid: NAP heights in the Netherlands sit about 43 m below the ellipsoid). Without a CRS the
//   root's frame is the sequences' own coordinates shifted to the centre (root.transform translates back).
//   The glTF vertices are the frame's (x, y, z) as glTF's y-up (x, z, -y), as 3D Tiles specifies.
// - index.html: a viewer (three.js r111 and its GLTFLoader from Debian's libjs-three, inlined) that reads
//   tileset.json, loads every content and shows them; it needs the files over HTTP (`python3 -m http.server -d DIR`)
//   or a browser that may read local files. When all are in it sets document.title to
//   "hsr: 3D tiles K/N contents, B buildings, E errors" and body data-hsr-done="1" (tests read these).
#pragma once

#include <string>
#include <vector>

namespace hsr {

struct Tiles3dParams {
  /// EPSG:N of the sequences' coordinates when they name none (or to override theirs); "" none.
  std::string crs;
  /// Place the tileset on the earth (ECEF) when a CRS is known; false: the sequences' own frame.
  bool earth_fixed = true;
};

struct Tiles3dSummary {
  std::size_t contents = 0, buildings = 0, triangles = 0;
  bool earth_fixed = false;  ///< root.transform goes to ECEF
  std::string crs;           ///< the CRS used ("" none)
};

/// Writes DIR/tileset.json, DIR/NAME.glb per sequence (NAME: the file's stem, made unique) and DIR/index.html;
/// each file atomic. Throws Error(BadInput, "tiles3d") for no sequence, a sequence without buildings, a CRS that
/// cannot be brought to ECEF, or sequences in different CRSs; io's errors for unreadable sequences.
Tiles3dSummary write_3d_tiles(const std::vector<std::string>& sequences, const std::string& dir, const Tiles3dParams& params = {});

}  // namespace hsr
