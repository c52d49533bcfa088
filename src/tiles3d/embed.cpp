// The viewer's files embedded at build time (the page must work offline): GLTFLoader from Debian's libjs-three
// and the page template. three.js and OrbitControls are the report stage's (src/report/embed.cpp).
// HSR_GLTF_LOADER_JS / HSR_TILES_VIEWER_TEMPLATE are absolute paths set by CMakeLists.txt.

#define HSR_STR2(x) #x
#define HSR_STR(x) HSR_STR2(x)

#define HSR_EMBED(symbol, path)                                   \
  __asm__(".section .rodata\n"                                    \
          ".global " #symbol "\n"                                 \
          ".type " #symbol ", @object\n"                          \
          ".balign 16\n" #symbol ":\n"                            \
          ".incbin \"" path "\"\n"                                \
          ".byte 0\n"                                             \
          ".size " #symbol ", . - " #symbol "\n"                  \
          ".previous\n")

HSR_EMBED(hsr_gltf_loader_js, HSR_STR(HSR_GLTF_LOADER_JS));
HSR_EMBED(hsr_tiles_viewer_template, HSR_STR(HSR_TILES_VIEWER_TEMPLATE));
