// The viewer's files embedded at build time (the page must work offline): GLTFLoader from Debian's libjs-three
// and the page template. three.js and OrbitControls are the report stage's (src/report/embed.cpp).
// HSR_GLTF_LOADER_JS / HSR_TILES_VIEWER_TEMPLATE are absolute paths set by CMakeLists.txt.

#include "core/embed.h"

HSR_EMBED(hsr_gltf_loader_js, HSR_STR(HSR_GLTF_LOADER_JS));
HSR_EMBED(hsr_tiles_viewer_template, HSR_STR(HSR_TILES_VIEWER_TEMPLATE));
