#pragma once
// Whether the tests are built under a sanitizer (CMake's CELL_UNDER_SANITIZER): it runs the
// geometry 20 to 30 times slower, so property tests ask fewer cases there (all of them in
// Release), and its allocator keeps freed memory (ASan's quarantine, TSan's shadow), so
// resident memory says nothing about the program's there.

namespace test {

#ifdef CELL_UNDER_SANITIZER
constexpr bool kUnderSanitizers = true;
#else
constexpr bool kUnderSanitizers = false;
#endif

}  // namespace test
