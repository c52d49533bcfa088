// hsr's modules: the parts that need a large library, built as shared objects beside the program and loaded
// the first time they are called (DECISIONS #188).
//
// Why: GDAL (footprints, rasters, CRSs) brings about 110 shared libraries and Xerces-C (E57's XML) about 40.
// Linked into the program, every `hsr` run maps and relocates them before main(): 34 MB of memory and about
// 0.1 s of CPU for `hsr --version`, more than a small scan's whole reconstruction, paid by runs that never read
// a footprint or an E57 file. As modules they cost only the runs that use them.
//
// A module is `libhsr_<name>.so`: `gdal` (city/footprints_gdal.cpp, io/raster_gdal.cpp,
// tiles3d/crs_gdal.cpp) and `xml` (io/e57_xml.cpp). Its entry points are `extern "C"` functions (HSR_MODULE_ENTRY)
// whose types the caller and the module share through one header each; what crosses is plain data and
// hsr::Error (core/error.h, header only). A module uses only header-only parts of hsr, so it holds no copy of
// the program's state (its link fails on any symbol left undefined).
#pragma once

#include <string>

/// Marks a module's entry point: C linkage (found by its plain name) and exported.
#define HSR_MODULE_ENTRY extern "C" __attribute__((visibility("default")))

namespace hsr {

/// The address of `symbol` in module `name`, which is loaded (once per process, thread-safe) from the
/// directory of the program or library holding this code, else from the build tree it was built in. Throws
/// Error(Internal, "modules") with one line naming the file and the loader's reason when it cannot be loaded
/// or has no such symbol. A module, once loaded, stays loaded.
void* module_symbol(const std::string& name, const char* symbol);

/// module_symbol as a function of type F, the type the entry point's header declares.
template <class F>
F* module_function(const std::string& name, const char* symbol) {
  return reinterpret_cast<F*>(module_symbol(name, symbol));
}

}  // namespace hsr
