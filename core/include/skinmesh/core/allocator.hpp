// How the process's memory allocator returns freed memory (a process-wide
// setting: programs call it once at start, a library never does).
#pragma once

namespace skinmesh {

// Large blocks (64 KiB and up) get their own pages and go back to the system
// when freed. glibc otherwise raises this threshold as large blocks are freed,
// after which they come from the heap and their pages stay resident, well
// above the live heap; with this set the resident peak stays near it, at
// the same speed. Does nothing on other C libraries.
void return_large_blocks_to_system();

}  // namespace skinmesh
