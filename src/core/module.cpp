// Loading hsr's modules on first use (module.h).
#include "core/module.h"

#include "core/error.h"

#include <dlfcn.h>

#include <filesystem>
#include <map>
#include <mutex>
#include <vector>

#ifndef HSR_MODULE_DIR
#define HSR_MODULE_DIR ""
#endif

namespace hsr {

namespace {

std::mutex& modules_mutex() {
  static std::mutex m;
  return m;
}

/// Loaded modules by name (handles are never closed: their functions may be held anywhere).
std::map<std::string, void*>& loaded_modules() {
  static std::map<std::string, void*> m;
  return m;
}

/// The folders a module is looked for in: that of the object holding this code (the `hsr` program, or the
/// Python extension), then the build tree's (HSR_MODULE_DIR), where tests and the Python module find it.
std::vector<std::filesystem::path> module_dirs() {
  std::vector<std::filesystem::path> dirs;
  Dl_info info{};
  if (dladdr(reinterpret_cast<void*>(&module_dirs), &info) && info.dli_fname && *info.dli_fname) {
    std::error_code ec;
    const std::filesystem::path self = std::filesystem::canonical(info.dli_fname, ec);
    if (!ec) dirs.push_back(self.parent_path());
  }
  if (*HSR_MODULE_DIR && (dirs.empty() || dirs.front() != std::filesystem::path(HSR_MODULE_DIR))) dirs.emplace_back(HSR_MODULE_DIR);
  return dirs;
}

void* load_module(const std::string& name) {
  const std::string file = "libhsr_" + name + ".so";
  const std::vector<std::filesystem::path> dirs = module_dirs();
  std::string reason = "not found";
  for (const std::filesystem::path& dir : dirs) {
    const std::filesystem::path path = dir / file;
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) continue;
    if (void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL)) return handle;
    const char* why = dlerror();
    reason = why ? why : "dlopen failed";
    break;
  }
  std::string where;
  for (const std::filesystem::path& dir : dirs) where += (where.empty() ? "" : ", ") + dir.string();
  throw Error(Status::Internal, "modules", "cannot load " + file + " (looked in " + where + "): " + reason);
}

}  // namespace

void* module_symbol(const std::string& name, const char* symbol) {
  std::lock_guard<std::mutex> lock(modules_mutex());
  void*& handle = loaded_modules()[name];
  if (!handle) handle = load_module(name);
  dlerror();
  void* address = dlsym(handle, symbol);
  if (!address) throw Error(Status::Internal, "modules", "libhsr_" + name + ".so has no entry point " + symbol);
  return address;
}

}  // namespace hsr
