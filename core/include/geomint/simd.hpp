#pragma once
// Vector width chosen at run time, with the same bits at every width.
//
// The ensembles step many trajectories at once in structure-of-arrays form. Their kernels are written once,
// as plain loops over trajectories that call the schemes' own scalar step templates, and compiled several
// times by GCC function multiversioning (the `target` attribute): baseline x86-64 (SSE2), x86-64-v3 (AVX2)
// and x86-64-v4 (AVX-512). GCC vectorizes each copy for its instruction set; `best_simd()` picks the widest
// the CPU has (cpuid, via __builtin_cpu_supports) and a caller may ask for any narrower one.
//
// Why the bits do not change with the width: a vectorized loop performs, lane by lane, the IEEE operations
// of the scalar code (+, -, *, /, sqrt and comparisons are correctly rounded at every width), never
// reassociated (no -ffast-math), and with floating-point contraction off (-ffp-contract=off for the whole
// project, so no FMA in the AVX2/AVX-512 copies either). Transcendental functions (sin, cos, atan2, exp) stay
// out of the vector loops: they are called through libm, one lane at a time, exactly as the scalar path does.
// tests/studies/simd_ensemble.test.cpp compares every width, the one-at-a-time path and threads, bit for bit.
//
// Why GCC multiversioning and not a SIMD library (xsimd): the kernels then are the scalar formulas, not a
// second restatement of them in batch types, so there is one formula per scheme and nothing to keep in sync.
// The price is trusting the auto-vectorizer, which the benchmark checks (`make bench`: ratio to a
// hand-written vector loop).
#include <string>
#include <utility>
#include <vector>

namespace geomint {

// scalar: one trajectory at a time through the library's scalar path (the systems' closed-form loops);
// sse2, avx2, avx512: the structure-of-arrays kernels compiled for that instruction set.
enum class Simd { scalar, sse2, avx2, avx512 };

const char* to_string(Simd s);
Simd parse_simd(const std::string& name);  // InputError for an unknown name
bool simd_supported(Simd s);               // does this CPU run it
Simd best_simd();                          // the widest supported (sse2 off x86-64)
std::vector<Simd> supported_simd();        // every supported one, scalar first

#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define GEOMINT_MULTIVERSION 1
#define GEOMINT_TARGET_AVX2 __attribute__((target("arch=x86-64-v3")))
#define GEOMINT_TARGET_AVX512 __attribute__((target("arch=x86-64-v4", "prefer-vector-width=512")))
#else
#define GEOMINT_MULTIVERSION 0
#define GEOMINT_TARGET_AVX2
#define GEOMINT_TARGET_AVX512
#endif
// A kernel body must be inlined into each compiled copy to be vectorized for its instruction set.
#define GEOMINT_KERNEL_INLINE inline __attribute__((always_inline))

namespace simd_detail {
template <class Kernel, class... Args>
void run_sse2(Args&&... args) {
  Kernel::run(std::forward<Args>(args)...);
}
template <class Kernel, class... Args>
GEOMINT_TARGET_AVX2 void run_avx2(Args&&... args) {
  Kernel::run(std::forward<Args>(args)...);
}
template <class Kernel, class... Args>
GEOMINT_TARGET_AVX512 void run_avx512(Args&&... args) {
  Kernel::run(std::forward<Args>(args)...);
}
}  // namespace simd_detail

// Runs Kernel::run(args...) (a static GEOMINT_KERNEL_INLINE function) compiled for `s` (sse2 for scalar,
// which callers handle themselves; a width the CPU lacks is an InputError from the caller's check).
template <class Kernel, class... Args>
void simd_dispatch(Simd s, Args&&... args) {
#if GEOMINT_MULTIVERSION
  if (s == Simd::avx512) return simd_detail::run_avx512<Kernel>(std::forward<Args>(args)...);
  if (s == Simd::avx2) return simd_detail::run_avx2<Kernel>(std::forward<Args>(args)...);
#endif
  (void)s;
  simd_detail::run_sse2<Kernel>(std::forward<Args>(args)...);
}

}  // namespace geomint
