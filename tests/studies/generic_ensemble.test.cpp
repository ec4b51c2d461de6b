// Ensembles of any registered system (generic_ensemble.hpp): run k has the bits of that run alone, whatever the
// threads and the share of runs computed together; the perturbations are uniform and a pure function of
// (seed, k); bad perturbations are refused before any work; a run that fails is data, not the end of the ensemble.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>

#include "geomint/error.hpp"
#include "geomint/generic_ensemble.hpp"

using namespace geomint;

namespace {

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }
bool same_bits(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0);
}
bool same_bits(const EnsembleRun& a, const EnsembleRun& b) {
  return a.k == b.k && same_bits(a.values, b.values) && a.failure == b.failure && same_bits(a.q, b.q) &&
         same_bits(a.v, b.v) && same_bits(a.z, b.z) && same_bits(a.energy0, b.energy0) &&
         same_bits(a.energy, b.energy) && same_bits(a.max_phi_d, b.max_phi_d) &&
         same_bits(a.newton_mean, b.newton_mean);
}

EnsembleSpec knife_edge_spec(const std::string& scheme, long runs) {
  EnsembleSpec spec;
  spec.base = {{"T", 5}};
  spec.perturb = {{"theta0", 1e-2}, {"u0", 1e-2}, {"alpha", 0.05}};
  spec.scheme = scheme;
  spec.h = 0.1;
  spec.path = Path::generic;
  spec.runs = runs;
  spec.seed = 7;
  return spec;
}

}  // namespace

TEST_CASE("ensemble: run k has the bits of that run alone, for any threads and any share", "[ensemble]") {
  const SystemInfo& sys = find_system("knife-edge");
  for (const std::string scheme : {"la", "contact", "yoshida4:la-trapezoid"}) {
    INFO(scheme);
    const EnsembleSpec spec = knife_edge_spec(scheme, 9);
    validate_ensemble(sys, spec);
    const auto one = run_ensemble(sys, spec, 0, spec.runs, 1);
    const auto two = run_ensemble(sys, spec, 0, spec.runs, 2);
    const auto tail = run_ensemble(sys, spec, 4, spec.runs, 3);  // the share of a second rank
    REQUIRE(one.size() == 9);
    REQUIRE(tail.size() == 5);
    for (long k = 0; k < spec.runs; ++k) {
      INFO("run " << k);
      const EnsembleRun& r = one[static_cast<std::size_t>(k)];
      REQUIRE(r.ok());
      CHECK(r.k == k);
      CHECK(same_bits(r, two[static_cast<std::size_t>(k)]));
      if (k >= 4) CHECK(same_bits(r, tail[static_cast<std::size_t>(k - 4)]));
      // the run alone, as `integrate` runs it from the same parameters
      const ParamValues pv = ensemble_params(sys, spec, k);
      const Run alone = sys.run(pv, scheme, spec.h, Path::generic, 1);
      const std::size_t last = alone.t.size() - 1;
      CHECK(same_bits(r.q, std::vector<double>(alone.q.begin() + 3 * static_cast<long>(last), alone.q.end())));
      CHECK(same_bits(r.v, std::vector<double>(alone.v.begin() + 3 * static_cast<long>(last), alone.v.end())));
      CHECK(same_bits(r.energy, alone.energy.back()));
      CHECK(same_bits(r.z, alone.z.back()));
      // the perturbed values are the base moved by spread * u, u from (seed, k)
      REQUIRE(r.values.size() == 3);
      CHECK(same_bits(r.values[0], 0.8 + 1e-2 * ensemble_sample(spec.seed, k, 0)));
      CHECK(same_bits(r.values[2], 0.1 + 0.05 * ensemble_sample(spec.seed, k, 2)));
      // and they differ from run to run: the runs are not copies of one another
      if (k > 0) CHECK(!same_bits(r.q, one[static_cast<std::size_t>(k - 1)].q));
      // what the MPI gather carries comes back with the same bits
      CHECK(same_bits(unpack_ensemble_run(pack(r)), r));
    }
    CHECK_THROWS_AS(unpack_ensemble_run(pack(one[0]) + "x"), InputError);
  }
}

TEST_CASE("ensemble: the perturbations are uniform between -1 and 1 and depend on (seed, run, parameter) only",
          "[ensemble]") {
  // mean 0 and variance 1/3 of U(-1, 1): the sample mean of n draws has standard error 1/sqrt(3n), the sample
  // variance 2/sqrt(45 n) (fourth moment 1/5); five of them is a bound a working generator meets except once in 1e6
  const long n = 200000;
  double sum = 0, sum2 = 0, lo = 1, hi = -1;
  long same_as_neighbour = 0;
  for (long k = 0; k < n; ++k) {
    const double u = ensemble_sample(3, k, 1);
    sum += u;
    sum2 += u * u;
    lo = std::min(lo, u);
    hi = std::max(hi, u);
    same_as_neighbour += u == ensemble_sample(3, k, 0) || u == ensemble_sample(4, k, 1);
  }
  const double mean = sum / n, var = sum2 / n - mean * mean;
  CHECK(std::abs(mean) < 5 / std::sqrt(3.0 * n));
  CHECK(std::abs(var - 1.0 / 3) < 5 * 2 / std::sqrt(45.0 * n));
  CHECK(lo >= -1);
  CHECK(hi < 1);
  CHECK(lo < -0.9999);
  CHECK(hi > 0.9999);
  CHECK(same_as_neighbour == 0);
  CHECK(same_bits(ensemble_sample(3, 17, 1), ensemble_sample(3, 17, 1)));
}

TEST_CASE("ensemble: bad perturbations are refused before any work, naming what to change", "[ensemble]") {
  const SystemInfo& sys = find_system("knife-edge");
  auto refused = [&](EnsembleSpec spec, const std::string& expect) {
    INFO(expect);
    try {
      validate_ensemble(sys, spec);
      FAIL("accepted");
    } catch (const InputError& e) {
      INFO(e.what());
      CHECK(std::string(e.what()).find(expect) != std::string::npos);
    }
  };
  EnsembleSpec spec = knife_edge_spec("la", 100);
  validate_ensemble(sys, spec);
  auto with = [&](std::vector<Perturbation> p) {
    EnsembleSpec s = spec;
    s.perturb = std::move(p);
    return s;
  };
  refused(with({{"mass", 1}}), "has no parameter 'mass'");
  refused(with({{"T", 1}}), "T is the horizon");
  refused(with({{"u0", 1}, {"u0", 2}}), "u0 is named twice");
  refused(with({{"u0", -1}}), "non-negative");
  refused(with({{"u0", std::nan("")}}), "non-negative");
  refused(with({}), "name what to perturb");
  // m = 1 moved by up to 2: some run has a negative mass; the first such run is named
  refused(with({{"m", 2}}), "run ");
  refused(with({{"m", 2}}), "lower the spreads");
  EnsembleSpec many = spec;
  many.runs = 0;
  refused(many, "runs must be");
  CHECK_THROWS_AS(parse_perturbation("u0"), InputError);
  CHECK_THROWS_AS(parse_perturbation("u0=1e-3x"), InputError);
  CHECK_THROWS_AS(parse_perturbation("=1"), InputError);
  CHECK(parse_perturbation("u0=1e-3").spread == 1e-3);
}

TEST_CASE("ensemble: a run that fails is recorded with where, and the others go on", "[ensemble]") {
  // The contact scheme on the oscillator amplifies q and p by about |1 - alpha h| per step once alpha h > 2, and
  // the action z, which accumulates h L ~ h |p|^2, by the square of that; a run of N = 500 steps overflows (a
  // non-finite state (q, p, z), which the run reports) once |1 - alpha h|^1000 > 1e308, that is
  // alpha > (1 + 10^(308/1000))/h = 30.3 at h = 0.1. alpha uniform in [15, 45): runs well below that reach T,
  // runs well above it fail, each saying at which step.
  const SystemInfo& sys = find_system("oscillator");
  EnsembleSpec spec;
  spec.base = {{"alpha", 30}};
  spec.perturb = {{"alpha", 15}};
  spec.scheme = "contact";
  spec.runs = 40;
  validate_ensemble(sys, spec);
  const auto runs = run_ensemble(sys, spec, 0, spec.runs, 2);
  long failed = 0;
  for (const auto& r : runs) {
    INFO("run " << r.k << ", alpha " << r.values[0] << ": " << r.failure);
    if (r.values[0] < 27) CHECK(r.ok());
    if (r.values[0] > 34) CHECK(!r.ok());
    if (!r.ok()) {
      ++failed;
      CHECK(r.failure.find("numerical failure at step") != std::string::npos);
      CHECK(r.q.empty());
    }
  }
  CHECK(failed > 0);
  CHECK(failed < spec.runs);
}
