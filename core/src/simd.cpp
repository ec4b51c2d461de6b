#include "geomint/simd.hpp"

#include "geomint/error.hpp"

namespace geomint {

const char* to_string(Simd s) {
  switch (s) {
    case Simd::scalar: return "scalar";
    case Simd::sse2: return "sse2";
    case Simd::avx2: return "avx2";
    case Simd::avx512: return "avx512";
  }
  return "?";
}

Simd parse_simd(const std::string& name) {
  for (Simd s : {Simd::scalar, Simd::sse2, Simd::avx2, Simd::avx512})
    if (name == to_string(s)) {
      require(simd_supported(s), "simd '" + name + "' is not supported by this CPU or build");
      return s;
    }
  if (name == "best") return best_simd();
  throw InputError("unknown simd '" + name + "' (known: best scalar sse2 avx2 avx512)");
}

bool simd_supported(Simd s) {
  switch (s) {
    case Simd::scalar:
    case Simd::sse2: return true;
#if GEOMINT_MULTIVERSION
    case Simd::avx2: return __builtin_cpu_supports("x86-64-v3") > 0;
    case Simd::avx512: return __builtin_cpu_supports("x86-64-v4") > 0;
#else
    default: return false;
#endif
  }
  return false;
}

Simd best_simd() {
  for (Simd s : {Simd::avx512, Simd::avx2})
    if (simd_supported(s)) return s;
  return Simd::sse2;
}

std::vector<Simd> supported_simd() {
  std::vector<Simd> v;
  for (Simd s : {Simd::scalar, Simd::sse2, Simd::avx2, Simd::avx512})
    if (simd_supported(s)) v.push_back(s);
  return v;
}

}  // namespace geomint
