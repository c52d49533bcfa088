// Memory handed back between the units of a long run (a survey's tiles), so that each unit's peak starts from
// what the run holds, not from what the units before it left behind.
#pragma once

#include <cstddef>

namespace hsr {

/// Returns the heap's free pages to the system (glibc malloc_trim; elsewhere nothing). Why: glibc keeps memory a
/// large vector freed in its arenas (its mmap threshold grows after such a free, and the threads' arenas are
/// never shrunk), so a survey planned or written tile by tile held each tile's leftovers under the next tile's
/// peak: `hsr city` on four 1 km² tiles 257 → 322 MB over the tiles, 257–263 MB with this after each tile.
void release_free_memory();

/// The bytes the heap holds free, not handed back to the system (glibc's mallinfo2 over all its arenas: the free
/// chunks and the arenas' tops; elsewhere 0).
std::size_t free_heap_bytes();

/// release_free_memory when the heap holds more than `kept_bytes` free (free_heap_bytes), or when malloc is TBB's
/// scalable allocator (its proxy preloaded, whose caches glibc's figures do not see); returns whether it did.
/// Why: between many short units of work (a worker's buildings) handing every free page back costs a system call
/// per free chunk and a page fault per page when the next unit takes it again (`hsr city -j 1` on a 56-building
/// tile: 11,659 madvise calls, 200 a building; DECISIONS #200), while what a unit leaves is small.
bool release_free_memory_above(std::size_t kept_bytes);

}  // namespace hsr
