// Memory handed back between the units of a long run (memory.h).
#include "core/memory.h"

#include <cstdlib>  // defines __GLIBC__ on glibc

#if defined(__GLIBC__)
#include <dlfcn.h>
#include <malloc.h>
#include <tbb/scalable_allocator.h>  // the command's number only: the allocator is looked up, not linked
#endif

namespace hsr {

void release_free_memory() {
#if defined(__GLIBC__)
  // In a process that allocates with TBB's scalable allocator (the launcher's with HSR_WORKER_MALLOC=tbb,
  // DECISIONS #181) its caches go back first; the lookup finds nothing elsewhere.
  using Command = int (*)(int, void*);
  if (auto command = reinterpret_cast<Command>(dlsym(RTLD_DEFAULT, "scalable_allocation_command")))
    command(TBBMALLOC_CLEAN_ALL_BUFFERS, nullptr);
  malloc_trim(0);
#endif
}

}  // namespace hsr
