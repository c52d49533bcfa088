// Files embedded into the binary at build time (the report page must work offline and the CLI must not
// depend on where Debian put three.js at run time). Each becomes a NUL-terminated char array.
// HSR_THREE_JS / HSR_ORBIT_CONTROLS_JS / HSR_REPORT_TEMPLATE are absolute paths set by CMakeLists.txt; a
// missing three.js is replaced by an empty file there, and report.cpp then refuses to write pages.

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

HSR_EMBED(hsr_three_js, HSR_STR(HSR_THREE_JS));
HSR_EMBED(hsr_orbit_controls_js, HSR_STR(HSR_ORBIT_CONTROLS_JS));
HSR_EMBED(hsr_report_template, HSR_STR(HSR_REPORT_TEMPLATE));
