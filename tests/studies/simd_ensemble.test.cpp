// The vectorized ensembles give the scalar path's bits: every oscillator scheme and both Foucault schemes with
// both constraint discretizations, at every vector width this CPU has and on one and two threads, compared bit
// for bit with one trajectory at a time (the library's scalar steps, compiled for baseline x86-64).
#include <catch2/catch.hpp>

#include <cstring>

#include "geomint/constants.hpp"
#include "geomint/oscillator_ensemble.hpp"
#include "geomint/foucault_ensemble.hpp"
#include "geomint/systems/oscillator.hpp"
#include "geomint/simd.hpp"

using namespace geomint;

namespace {

bool same_bits(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0;
}

template <class Scheme>
void check_oscillator(double h, double alpha) {
  // 1003 trajectories: not a multiple of any vector width or of the kernel's block, so the loops' tails run too
  const std::size_t M = 1003;
  const long steps = 700;
  auto init = [&] {
    OscEnsemble e(M);
    for (std::size_t i = 0; i < M; ++i) {
      e.q[i] = -0.25 + 1e-3 * static_cast<double>(i);
      e.p[i] = 0.75 - 2e-3 * static_cast<double>(i);
      e.z[i] = 1e-4 * static_cast<double>(i);
    }
    return e;
  };
  // the reference: OscState and Scheme::step, trajectory by trajectory, as the oscillator's run_fast runs them
  OscEnsemble ref = init();
  for (std::size_t i = 0; i < M; ++i) {
    OscState<double> s{ref.q[i], ref.p[i], ref.z[i]};
    for (long j = 0; j < steps; ++j) Scheme::step(s, h, alpha);
    ref.q[i] = s.q;
    ref.p[i] = s.p;
    ref.z[i] = s.z;
  }
  for (Simd w : supported_simd())
    for (unsigned threads : {1u, 2u}) {
      OscEnsemble e = init();
      step_ensemble<Scheme>(e, steps, h, alpha, threads, w);
      INFO(Scheme::name << " " << to_string(w) << " threads " << threads);
      CHECK(same_bits(e.q, ref.q));
      CHECK(same_bits(e.p, ref.p));
      CHECK(same_bits(e.z, ref.z));
    }
}

}  // namespace

TEST_CASE("oscillator ensembles: every width and thread count gives the scalar path's bits", "[simd]") {
  INFO("widths on this CPU: best " << to_string(best_simd()));
  for (double alpha : {0.01, 1.0}) {
    check_oscillator<systems::Oscillator::La>(0.1, alpha);
    check_oscillator<systems::Oscillator::LaPrinted>(0.1, alpha);
    check_oscillator<systems::Oscillator::Contact>(0.1, alpha);
    check_oscillator<systems::Oscillator::Leapfrog>(0.1, alpha);
    check_oscillator<systems::Oscillator::LaMidpoint>(0.1, alpha);
    check_oscillator<systems::Oscillator::ContactSymmetric>(0.1, alpha);
    check_oscillator<systems::Oscillator::ConformalStrang>(0.1, alpha);
  }
  // decaying into subnormals (alpha = 1, long run) must not change the bits either
  check_oscillator<systems::Oscillator::Contact>(0.5, 1.0);
}

TEST_CASE("the machine's widest vectors are used when asked for", "[simd]") {
  CHECK(simd_supported(Simd::scalar));
  CHECK(simd_supported(Simd::sse2));
  CHECK(simd_supported(best_simd()));
  CHECK(parse_simd("best") == best_simd());
  CHECK_THROWS_AS(parse_simd("avx1024"), InputError);
}

TEST_CASE("Foucault anomaly ensembles: every width and thread count gives the per-run path's bits", "[simd][foucault]") {
  systems::FoucaultPendulum base;
  base.T = 400;  // 4000 and 8000 steps: ~50 passes through the origin, 62 and 125 rotation anchors
  // 140 runs per cell: one full batch of 128 lanes and a partial one (12 lanes, stepped as 16)
  const auto cases = anomaly_cases({0.1, 0.05}, {1e-3, 1e-4}, {"la-nh", "contact-nh"},
                                   {systems::Foucault::name, systems::FoucaultRotation::name}, 140);
  const double threshold = 0.01 * geomint::pi / 180;
  const auto ref = run_anomaly_ensemble(base, cases, threshold, 1, {}, Simd::scalar);
  long jumps = 0, turns = 0;
  for (const auto& r : ref) {
    REQUIRE(r.status == "ok");
    jumps += static_cast<long>(r.jumps.size());
    turns += r.summary.half_swings;
  }
  CHECK(jumps > 2000);  // the comparison covers recorded jumps and landings, not only smooth runs
  CHECK(turns > 100000);
  for (Simd w : supported_simd())
    for (unsigned threads : {1u, 2u}) {
      if (w == Simd::scalar && threads == 1) continue;
      const auto got = run_anomaly_ensemble(base, cases, threshold, threads, {}, w);
      REQUIRE(got.size() == ref.size());
      long differ = 0;
      for (std::size_t i = 0; i < ref.size(); ++i) differ += same_bits(got[i], ref[i]) ? 0 : 1;
      INFO(to_string(w) << " threads " << threads);
      CHECK(differ == 0);
    }
}

TEST_CASE("Foucault ensembles: a failing run fails at the same step with the same message at every width",
          "[simd][foucault]") {
  systems::FoucaultPendulum base;
  base.T = 200;
  // contact with h alpha = 3: the (1 - h alpha) factor of (18) is -2, the run overflows after ~1000 steps
  const auto cases = anomaly_cases({0.1}, {30.0}, {"contact-nh"},
                                   {systems::Foucault::name, systems::FoucaultRotation::name}, 5);
  const auto ref = run_anomaly_ensemble(base, cases, 0.1, 1, {}, Simd::scalar);
  for (const auto& r : ref) {
    INFO(r.status);
    CHECK(r.status.find("numerical failure at step") != std::string::npos);
  }
  for (Simd w : supported_simd()) {
    const auto got = run_anomaly_ensemble(base, cases, 0.1, 2, {}, w);
    for (std::size_t i = 0; i < ref.size(); ++i) {
      INFO(to_string(w) << ": " << got[i].status << " vs " << ref[i].status);
      CHECK(same_bits(got[i], ref[i]));
    }
  }
}
