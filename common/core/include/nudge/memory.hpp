#pragma once

namespace nudge {

// Keeps the process's freed large blocks (images: a 1280x960 colour still is 3.7 MB, its mask
// 1.2 MB) in the heap for the next allocation instead of handing them back to the kernel.
//
// Why: glibc maps a block above its mmap threshold (128 KB at first) fresh from the kernel and
// unmaps it when freed, so every such image costs a page fault per 4 KB page on first touch, and
// the heap's top is trimmed back likewise. On virtual machines a page fault is dear: on an AMD EPYC
// host (docs/benchmarks.md, "Page faults") a learning run's still pair took 11 ms of CPU to
// segment, and 5.3 ms with the blocks kept. Every service calls this at start
// (bus::guarded_main); a program without the bus may call it too. Memory a process touches for
// the first time still faults in: Supervisor::warm_up touches the grasp plan's before it counts.
//
// Sets glibc's M_MMAP_THRESHOLD to its largest (32 MB: larger blocks are still mapped) and
// M_TRIM_THRESHOLD to 1 GB; the process's resident size then stays near its peak. Returns false
// where the C library refused (a non-glibc libc: nothing changes). Safe to call more than once.
bool keep_large_buffers_for_reuse();

}  // namespace nudge
