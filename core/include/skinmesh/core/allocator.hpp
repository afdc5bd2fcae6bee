// How the process's memory allocator returns freed memory (a process-wide
// setting: programs call one of these at start, a library never does).
#pragma once

namespace skinmesh {

// Large blocks (64 KiB and up) get their own pages and go back to the system
// when freed. glibc otherwise raises this threshold as large blocks are freed,
// after which they come from the heap and their pages stay resident, well
// above the live heap; with this set the resident peak stays near it, at
// the same speed. For one mesh (skinmesh mesh, volume). Does nothing on
// other C libraries.
void return_large_blocks_to_system();

// Blocks up to 32 MiB come from the heap and freed ones stay there for the
// next: for work that frees and allocates the same large lists again and
// again (the frames of a morph or a trajectory: copies of a frame's mesh, a
// complex each step). Mapping each afresh makes the kernel zero its pages
// one fault at a time: on bench_moving's 3mht hinge at 41 frames a frame
// took 1.17 s that way, 0.65-0.74 s with this, and 0.84-0.86 s with the
// heap's top given back at glibc's default (128 KiB free); resident peak
// 225, 270-276 and 253-256 MB. Does nothing on other C libraries.
void keep_large_blocks_for_reuse();

}  // namespace skinmesh
