#pragma once
// Long damped runs decay into subnormal numbers, where x86 arithmetic is tens of times slower.
// ScopedFlushToZero sets flush-to-zero and denormals-are-zero for the current thread for its lifetime
// (x86-64 SSE; a no-op elsewhere). Results change only below DBL_MIN ~ 2.2e-308.
#if defined(__x86_64__) || defined(__SSE2__)
#include <xmmintrin.h>
#define GEOMINT_HAVE_MXCSR 1
#endif

namespace geomint {

class ScopedFlushToZero {
 public:
  ScopedFlushToZero() {
#ifdef GEOMINT_HAVE_MXCSR
    saved_ = _mm_getcsr();
    _mm_setcsr(saved_ | 0x8040u);  // FTZ (bit 15) | DAZ (bit 6)
#endif
  }
  ~ScopedFlushToZero() {
#ifdef GEOMINT_HAVE_MXCSR
    _mm_setcsr(saved_);
#endif
  }
  ScopedFlushToZero(const ScopedFlushToZero&) = delete;
  ScopedFlushToZero& operator=(const ScopedFlushToZero&) = delete;

 private:
  unsigned saved_ = 0;
};

}  // namespace geomint
