// Memory handed back between the units of a long run (memory.h).
#include "core/memory.h"

#include <cstdlib>  // defines __GLIBC__ on glibc

#if defined(__GLIBC__)
#include <dlfcn.h>
#include <malloc.h>
#include <tbb/scalable_allocator.h>  // the command's number only: the allocator is looked up, not linked
#endif

namespace hsr {

#if defined(__GLIBC__)
namespace {
using Command = int (*)(int, void*);
/// TBB's scalable_allocation_command where its allocator is loaded (looked up, not linked); null elsewhere. TBB
/// loads it for its own containers even where malloc is glibc's.
Command tbb_allocation_command() {
  return reinterpret_cast<Command>(dlsym(RTLD_DEFAULT, "scalable_allocation_command"));
}
/// Whether malloc itself is TBB's (its proxy preloaded: the launcher's with HSR_WORKER_MALLOC=tbb, DECISIONS #181).
bool malloc_is_tbbs() { return dlsym(RTLD_DEFAULT, "__TBB_malloc_proxy") != nullptr; }
}  // namespace
#endif

void release_free_memory() {
#if defined(__GLIBC__)
  // TBB's caches go back first where its allocator is in use
  if (const Command command = tbb_allocation_command()) command(TBBMALLOC_CLEAN_ALL_BUFFERS, nullptr);
  malloc_trim(0);
#endif
}

std::size_t free_heap_bytes() {
#if defined(__GLIBC__)
  return mallinfo2().fordblks;
#else
  return 0;
#endif
}

bool release_free_memory_above(std::size_t kept_bytes) {
#if defined(__GLIBC__)
  if (!malloc_is_tbbs() && free_heap_bytes() <= kept_bytes) return false;
  release_free_memory();
  return true;
#else
  (void)kept_bytes;
  return false;
#endif
}

}  // namespace hsr
