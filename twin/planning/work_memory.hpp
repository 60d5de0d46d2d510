#pragma once
// Planning allocates and frees work buffers of more than 128 KB many times over (a mesh's
// triangle boxes, the simplex's factorization, the verifier's trees). glibc gives such blocks
// back to the system when they are freed and takes them again on the next allocation, and every
// page taken again is a page fault (11 us each on the cell's virtual machines: 2.4 ms of a
// 20 ms plan). A planning process keeps them instead: call once at the start of main.

#include <malloc.h>

namespace twin {

inline void keep_work_memory() {
  mallopt(M_MMAP_THRESHOLD, 32 << 20);  // blocks up to 32 MB come from the heap
  mallopt(M_TRIM_THRESHOLD, 64 << 20);  // and the heap keeps up to 64 MB free
}

}  // namespace twin
