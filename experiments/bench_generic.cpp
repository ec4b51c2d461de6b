// Benchmark (make bench): the generic Newton step built from a system's Lagrangian against the hand-derived
// closed form of the same scheme, ns per step, Newton updates and Jacobians per step; and the generic step alone
// on the systems without a closed form. The damped systems are timed both in one long run and in runs of their
// own horizon T (the regime a study sees; see run_generic). Timed with Google Benchmark (medians over interleaved repetitions); every
// ratio is between medians of this run.
//   bench_generic [--steps 200000] [--reps 9] [--out out] [--benchmark_filter=...]
// Writes out/bench_generic.tsv (every case) and out/bench_generic_ratios.tsv (generic / closed form).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <tuple>

#include "bench_table.hpp"
#include "geomint/cli.hpp"
#include "geomint/error.hpp"
#include "geomint/generic/stepper.hpp"
#include "geomint/io.hpp"
#include "geomint/systems/foucault.hpp"
#include "geomint/systems/knife_edge.hpp"
#include "geomint/systems/nonholonomic_particle.hpp"
#include "geomint/systems/oscillator.hpp"
#include "geomint/systems/pendulum.hpp"
#include "geomint/timing.hpp"

using namespace geomint;

namespace {

struct Counts {
  double updates, jacobians;  // per step
};

struct Pair {
  std::string system, scheme, closed, closed_case, generic_case;
  std::string regime = "one run";  // or "runs of T": restarted at the system's horizon (see run_generic)
  double newton = missing_value;     // Newton updates per step of the generic step
  double jacobians = missing_value;  // Jacobians assembled per step
  void set(const Counts& c) {
    newton = c.updates;
    jacobians = c.jacobians;
  }
};

// N generic steps from the system's initial data, as consecutive runs of `per` steps (each from the initial
// data with a new stepper, as a study's runs are); returns the Newton updates and Jacobians per step. A damped
// system run far past its horizon decays into subnormal numbers (the knife edge at h = 0.1 reaches 1e-44 after
// 20000 steps), where a step costs what it costs there and Newton needs fewer updates: the "runs of T" rows
// time the steps a study over the system's own horizon takes.
template <class Sys, class G>
Counts run_generic(const Sys& sys, double h, long N, long per = 0) {
  if (per <= 0) per = N;
  long updates = 0, jacobians = 0;
  double last = 0;
  for (long done = 0; done < N; done += per) {
    generic::Stepper<Sys, G> st(sys, h);
    st.start(sys.template initial_position<double>(), sys.template initial_velocity<double>());
    const long steps = std::min(per, N - done);
    for (long j = 0; j < steps; ++j) st.step();
    updates += st.total_updates();
    jacobians += st.jacobians();
    last += st.state().q(0);
  }
  do_not_optimize(last);
  return {double(updates) / double(N), double(jacobians) / double(N)};
}

}  // namespace

int main(int argc, char** argv) {
  return guarded_main("bench_generic", [&] {
    auto args = bench::Table::split_args(argc, argv);
    long N = 200000;
    int reps = 9;
    Cli cli("bench_generic", "ns per step of the generic Newton step against the closed forms");
    cli.options.add_options()("steps", po::value(&N)->default_value(N), "steps per timed call (oscillator)")(
        "reps", po::value(&reps)->default_value(reps), "timed repetitions (median reported)");
    if (!cli.parse(argc, args.data())) return 0;
    require(N >= 1000 && N <= 100000000, "steps must be in [1000, 1e8]");
    require(reps >= 3 && reps <= 1000, "reps must be in [3, 1000]");
    const auto dir = prepare_output_dir(cli.out);
    bench::Table table(reps, 0.05);
    std::vector<Pair> pairs;

    // The oscillator (h = 0.01, alpha = 0.1, as bench_steps): its five closed forms.
    systems::Oscillator osc;
    osc.alpha = 0.1;
    const double ho = 0.01;
    std::apply([&](auto... fp) {
      (([&] {
         using C = decltype(fp);
         using G = typename C::solves;
         const std::string scheme = generic::scheme_name<G>();
         // the closed form under the paper's name where it has one (leapfrog, contact-sym), else the scheme's
         const std::string closed = *generic::alias_of<C>() ? generic::alias_of<C>() : scheme;
         Pair p{"oscillator", scheme, closed, "closed oscillator " + closed, "generic oscillator " + scheme};
         table.add("oscillator", p.closed_case, double(N), [=] {
           double q = 0;
           osc.run_fast<C>(ho, N, [&](const auto& v) { q = v.q(0); });
           do_not_optimize(q);
         });
         table.add("oscillator", p.generic_case, double(N), [=] { run_generic<systems::Oscillator, G>(osc, ho, N); });
         p.set(run_generic<systems::Oscillator, G>(osc, ho, N));
         pairs.push_back(p);
       }()),
       ...);
    }, systems::Oscillator::fast_paths{});

    // The Foucault pendulum, both constraints: (15), (18) and the remedy, 1000 s at h = 0.1.
    const double hf = 0.1;
    const long Nf = 10000;
    auto foucault = [&](auto sys) {
      using Sys = decltype(sys);
      std::apply([&](auto... fp) {
        (([&] {
           using C = decltype(fp);
           using G = typename C::solves;
           const std::string scheme = generic::scheme_name<G>();
           Pair p{Sys::name, scheme, generic::alias_of<C>(), "closed " + std::string(Sys::name) + " " + generic::alias_of<C>(),
                  "generic " + std::string(Sys::name) + " " + scheme};
           const FoucaultParams<double> fp_(sys);
           const Vec2<double> q0(sys.x0, sys.y0), v0(sys.vx0, sys.vy0);
           table.add(Sys::name, p.closed_case, double(Nf), [=] {
             double last = 0;
             systems::run_closed_form<C>(sys, fp_, q0, v0, hf, Nf, FoucaultStart::legendre,
                                         [&](const FoucaultStep<double>& st) { last = st.qn(0); });
             do_not_optimize(last);
           });
           table.add(Sys::name, p.generic_case, double(Nf), [=] { run_generic<Sys, G>(sys, hf, Nf); });
           p.set(run_generic<Sys, G>(sys, hf, Nf));
           pairs.push_back(p);
         }()),
         ...);
      }, typename Sys::fast_paths{});
    };
    foucault(systems::Foucault{});
    foucault(systems::FoucaultRotation{});

    // The nonholonomic particle (h = 0.05): one run of 20000 steps, and runs of its horizon T = 10 (200 steps).
    {
      const systems::NonholonomicParticle sys;
      const double hp = 0.05;
      const long Np = 20000, per = std::lround(sys.T / hp);
      for (const long period : {Np, per}) {
        const bool runs = period < Np;
        const std::string tag = runs ? ", runs of T" : "";
        Pair p{"particle", "la", systems::NonholonomicParticle::La::name, "closed particle particle-la-nh" + tag,
               "generic particle la" + tag};
        if (runs) p.regime = "runs of T";
        table.add("particle", p.closed_case, double(Np), [=] {
          double last = 0;
          for (long done = 0; done < Np; done += period) {
            Vec<double, 3> q = sys.initial_position<double>(),
                           v = generic::consistent_velocity(sys, 0.0, q, sys.initial_velocity<double>());
            for (long j = 0; j < std::min(period, Np - done); ++j) systems::NonholonomicParticle::La::step(sys, q, v, hp);
            last += q(0);
          }
          do_not_optimize(last);
        });
        table.add("particle", p.generic_case, double(Np),
                  [=] { run_generic<systems::NonholonomicParticle, generic::LaLeft>(sys, hp, Np, period); });
        p.set(run_generic<systems::NonholonomicParticle, generic::LaLeft>(sys, hp, Np, period));
        pairs.push_back(p);
      }
    }

    // Systems without a closed form: the generic step alone (h = 0.1), one run of 20000 steps and runs of the
    // system's horizon T (pendulum and knife edge: T = 20, 200 steps).
    std::vector<Pair> alone;
    auto generic_only = [&](auto sys, long n_steps) {
      using Sys = decltype(sys);
      const long per = std::lround(double(sys.T) / 0.1);
      for (const long period : {n_steps, per}) {
        const bool runs = period < n_steps;
        std::apply([&](auto... g) {
          (([&] {
             using G = decltype(g);
             const std::string scheme = generic::scheme_name<G>();
             Pair p{Sys::name, scheme, "", "", "generic " + std::string(Sys::name) + " " + scheme + (runs ? ", runs of T" : "")};
             if (runs) p.regime = "runs of T";
             table.add(Sys::name, p.generic_case, double(n_steps), [=] { run_generic<Sys, G>(sys, 0.1, n_steps, period); });
             p.set(run_generic<Sys, G>(sys, 0.1, n_steps, period));
             alone.push_back(p);
           }()),
           ...);
        }, generic::AllSchemesTuple{});
      }
    };
    generic_only(systems::Pendulum{}, 20000);
    generic_only(systems::KnifeEdge{}, 20000);

    std::printf("Google Benchmark, medians of %d interleaved repetitions (ns per step):\n", reps);
    table.run();
    const Params params{{"steps_oscillator", std::to_string(N)}, {"reps", std::to_string(reps)},
                        {"oscillator", "alpha 0.1, h 0.01"}, {"foucault", "h 0.1, 10000 steps"},
                        {"particle", "h 0.05, 20000 steps; runs of T = 10"},
                        {"pendulum, knife-edge", "h 0.1, 20000 steps; runs of T = 20"}};
    table.write_tsv(dir / "bench_generic.tsv", "bench_generic", params);
    TsvWriter ratios(dir / "bench_generic_ratios.tsv", "bench_generic", params,
                     {"system", "scheme", "regime", "closed_form", "ns_closed", "ns_generic", "ratio", "newton_per_step",
                      "jacobians_per_step"});
    std::printf("\n%-18s %-18s %-10s %-16s %10s %10s %8s %8s %9s\n", "system", "scheme", "regime", "closed form", "closed",
                "generic", "ratio", "Newton", "Jacobians");
    for (const auto& p : pairs) {
      const double c = table.ns(p.closed_case), g = table.ns(p.generic_case);
      ratios.row(p.system, p.scheme, p.regime, p.closed, c, g, g / c, p.newton, p.jacobians);
      std::printf("%-18s %-18s %-10s %-16s %10.2f %10.2f %8.2f %8.3f %9.3f\n", p.system.c_str(), p.scheme.c_str(),
                  p.regime.c_str(), p.closed.c_str(), c, g, g / c, p.newton, p.jacobians);
    }
    for (const auto& p : alone) {
      const double g = table.ns(p.generic_case);
      ratios.row(p.system, p.scheme, p.regime, "-", missing_value, g, missing_value, p.newton, p.jacobians);
      std::printf("%-18s %-18s %-10s %-16s %10s %10.2f %8s %8.3f %9.3f\n", p.system.c_str(), p.scheme.c_str(),
                  p.regime.c_str(), "-", "-", g, "-", p.newton, p.jacobians);
    }
    ratios.commit();
    return 0;
  });
}
