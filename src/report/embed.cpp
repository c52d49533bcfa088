// Files embedded into the binary at build time (the report page must work offline and the CLI must not
// depend on where Debian put three.js at run time). Each becomes a NUL-terminated char array.
// HSR_THREE_JS / HSR_ORBIT_CONTROLS_JS / HSR_REPORT_TEMPLATE are absolute paths set by CMakeLists.txt; a
// missing three.js is replaced by an empty file there, and report.cpp then refuses to write pages.

#include "core/embed.h"

HSR_EMBED(hsr_three_js, HSR_STR(HSR_THREE_JS));
HSR_EMBED(hsr_orbit_controls_js, HSR_STR(HSR_ORBIT_CONTROLS_JS));
HSR_EMBED(hsr_report_template, HSR_STR(HSR_REPORT_TEMPLATE));
