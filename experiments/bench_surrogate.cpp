// What a surrogate costs (modified/surrogate.hpp): seconds to build it against the order K (the symbolic
// construction and its certification, as the surrogate program runs them), and a step of the scheme on the
// surrogate against a step of the same scheme on the base system, in one run.
//   bench_surrogate [--cases oscillator:la:4 oscillator:contact:4 pendulum:la-midpoint:4 knife-edge:la-midpoint:2
//                   foucault:la:2] [--systems-dir docs/systems]
//                   [--max-order 4] [--budget 300] [--h 0.01] [--reps 5] [--wp true] [--out out]
// A case is <system file in --systems-dir>:<scheme>[:<largest K>]; the pendulum is the conservative one, L = q'^2/2 + cos q.
// Construction: one run per K (wall and CPU seconds of this process: the machine is shared); a K whose build
// exhausts the budget stops the higher ones of that case. Steps: TimingStats of N = T/h steps (median of --reps),
// the base and the surrogate of the largest K built, Path::generic (the surrogate has no closed form). A timing
// program, run by `make bench`, never a test; the header records the load average.
// Writes out/bench_surrogate.tsv (case, scheme, K, build_seconds, build_cpu_seconds, reached, base_step_ns,
// surrogate_step_ns, ratio).
// Is it worth it (--wp, the default cases pendulum:la-midpoint and knife-edge:la-midpoint): work-precision points,
// max_j |q_j - q(t_j)| against the base's reference (Odeint, 1e-13) and the median CPU seconds of a run, for the
// scheme on the base, on its surrogates (K = 2, 4; the step parameter set to each h), its compositions yoshida4 and
// yoshida6a, and Odeint's dopri5 and Bulirsch–Stoer and GSL's rk8pd over tolerances (the work_precision study's
// points); the long horizon of the symmetric scheme on the conservative pendulum and on the knife edge without
// damping: max_j |E(q_j, v_j) - E_0| over T = 1000, and over its first tenth, E the base's energy; and the damping
// law of la and its surrogates K = 1, 2 on the paper's oscillator (alpha = 0.1) against the closed form's energy.
// Writes out/bench_surrogate_work_precision.tsv, out/bench_surrogate_energy.tsv and out/bench_surrogate_damping.tsv.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <string>
#include <vector>

#include "geomint/cli.hpp"
#include "geomint/error.hpp"
#include "geomint/formula/formula_registry.hpp"
#include "geomint/formula/model.hpp"
#include "geomint/io.hpp"
#include "geomint/modified/surrogate.hpp"
#include "geomint/work_precision.hpp"

using namespace geomint;

namespace {
double cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

std::shared_ptr<const formula::FormulaModel> base_model(const std::string& dir, const std::string& name) {
  if (name == "pendulum") {  // the conservative pendulum of the surrogate tests
    formula::SystemDescription d;
    d.name = "pendulum-conservative";
    d.coordinates = 1;
    d.parameters.push_back({"q0", formula::formula_text("1", "parameter q0"), "initial angle"});
    d.parameters.push_back({"T", formula::formula_text("10", "parameter T"), "horizon"});
    d.lagrangian = formula::formula_text("v1^2/2 + cos(q1)", "L");
    d.initial_q.push_back(formula::formula_text("q0", "q1"));
    d.initial_v.push_back(formula::formula_text("0", "v1"));
    return formula::compile_model(d);
  }
  return formula::load_system_file(dir + "/" + name + ".geomint");
}
}  // namespace

int main(int argc, char** argv) {
  return guarded_main("bench_surrogate", [&] {
    std::vector<std::string> cases{"oscillator:la:4", "oscillator:contact:4", "pendulum:la-midpoint:4",
                                   "knife-edge:la-midpoint:2", "foucault:la:2"};
    int max_order = 4, reps = 5;
    double budget = 300, h = 0.01;
    std::string systems_dir = "docs/systems";
    bool work = true;
    Cli cli("bench_surrogate", "seconds to build a surrogate against K, and its step against the base's");
    cli.options.add_options()("cases", po::value(&cases)->multitoken(), "cases <system>:<scheme>[:<largest K>]")(
        "systems-dir", po::value(&systems_dir)->default_value(systems_dir), "where the system files are")(
        "max-order", po::value(&max_order)->default_value(max_order), "largest K (1..5)")(
        "budget", po::value(&budget)->default_value(budget), "time budget of one build, seconds")(
        "h", po::value(&h)->default_value(h), "step of the timed runs")(
        "reps", po::value(&reps)->default_value(reps), "timed runs (median)")(
        "wp", po::value(&work)->default_value(work), "also the work-precision points and the pendulum's energy");
    if (!cli.parse(argc, argv)) return 0;
    require(max_order >= 1 && max_order <= 5, "--max-order must be in [1, 5]");
    require(reps >= 1 && reps <= 100, "--reps must be in [1, 100]");
    require(std::isfinite(budget) && budget > 0, "--budget must be a positive number of seconds");
    require(std::isfinite(h) && h > 0, "--h must be positive");

    struct Row {
      std::string system, scheme;
      int K, reached;
      double seconds, cpu, base_ns, surrogate_ns;
    };
    std::vector<Row> rows;
    for (const auto& c : cases) {
      const auto colon = c.find(':');
      require(colon != std::string::npos, "a case is <system>:<scheme>, got '" + c + "'");
      const std::string system = c.substr(0, colon);
      std::string scheme = c.substr(colon + 1);
      int top = max_order;
      if (const auto second = scheme.find(':'); second != std::string::npos) {
        top = std::min(top, std::atoi(scheme.c_str() + second + 1));
        scheme = scheme.substr(0, second);
      }
      const auto base = base_model(systems_dir, system);
      const auto binfo = formula::formula_system_info(base);
      binfo->scheme(scheme);
      for (int K = 1; K <= top; ++K) {
        const auto w0 = std::chrono::steady_clock::now();
        const double c0 = cpu_seconds();
        const auto s = modified::build_surrogate(base, scheme, K, budget);
        const double cpu = cpu_seconds() - c0;
        const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - w0).count();
        const auto sinfo = formula::formula_system_info(formula::compile_model(s.description));
        const double T = binfo->horizon({});
        const double steps = std::floor(T / h);
        const TimingStats tb = binfo->time_run({}, scheme, h, Path::generic, reps);
        const TimingStats ts = sinfo->time_run({{s.step_parameter, h}}, scheme, h, Path::generic, reps);
        rows.push_back({system, scheme, K, s.K, wall, cpu, 1e9 * tb.median / steps, 1e9 * ts.median / steps});
        std::printf("%-12s %-12s K = %d (reached %d): built in %7.2f s (%7.2f s CPU); step %7.0f ns against %7.0f ns (%.2fx)\n",
                    system.c_str(), scheme.c_str(), K, s.K, wall, cpu, rows.back().surrogate_ns, rows.back().base_ns,
                    rows.back().surrogate_ns / rows.back().base_ns);
        std::fflush(stdout);
        if (s.K < K) break;  // the construction stops here (budget, or a correction that cannot be made)
      }
    }
    // work-precision points of the base, its surrogates, compositions and adaptive baselines
    struct Point {
      std::string system, method;
      double knob, error, seconds;
    };
    std::vector<Point> wp;
    struct Energy {
      std::string system, method;
      double h, T, drift, drift_tenth;  // max_j |E_j - E_0| over [0, T] and over [0, T/10]
    };
    // max |E_j - E_0| over the run and over its first tenth: equal where the energy error is bounded, ten times
    // larger where it drifts linearly.
    auto energy_error = [](const SystemInfo& info, const ParamValues& q, const std::string& scheme, double hh) {
      const Run run = info.run(q, scheme, hh, Path::generic, 10);
      double d = 0, d10 = 0;
      const double T = run.t.back();
      for (std::size_t j = 0; j < run.energy.size(); ++j) {
        const double e = std::abs(run.energy[j] - run.energy.front());
        d = std::max(d, e);
        if (run.t[j] <= T / 10) d10 = std::max(d10, e);
      }
      return std::make_pair(d, d10);
    };
    struct Damping {
      std::string method;
      double h, T, rate_error, max_relative;  // slope of log(E_j / E(t_j)) in t; max_j |E_j / E(t_j) - 1|
    };
    std::vector<Damping> damping;
    std::vector<Energy> energy;
    if (work) {
      for (const std::string system : {"pendulum", "knife-edge"}) {
        const std::string scheme = "la-midpoint";
        const auto base = base_model(systems_dir, system);
        const auto binfo = formula::formula_system_info(base);
        WorkPrecisionOptions opt;
        opt.schemes = {scheme, "yoshida4:" + scheme, "yoshida6a:" + scheme};
        opt.hs = {0.2, 0.1, 0.05, 0.025, 0.0125};
        opt.baselines = {"odeint-dopri5", "odeint-bulirsch-stoer", "gsl-rk8pd"};
        opt.tols = {1e-4, 1e-6, 1e-8, 1e-10, 1e-12};
        opt.path = Path::generic;
        opt.reps = reps;
        opt.reference = ReferenceKind::odeint;
        const ParamValues pv{{"T", 10.0}};
        check_work_precision(*binfo, {pv}, opt);
        for (const auto& p : work_precision_study(*binfo, {pv}, opt).points)
          wp.push_back({system, p.method, p.value, p.errors.empty() ? WorkPoint::nan : p.errors[0], p.time.median});
        for (int K : {2, 4}) {
          if (system == "knife-edge" && K == 4) continue;  // a minute per order there: K = 2 is the table's row
          const auto s = modified::build_surrogate(base, scheme, K, budget);
          const auto sinfo = formula::formula_system_info(formula::compile_model(s.description));
          const std::string name = "surrogate" + std::to_string(s.K) + ":" + scheme;
          for (double hh : opt.hs) {
            const long N = std::lround(10.0 / hh);
            const Reference ref = binfo->reference(pv, hh, N, ReferenceKind::odeint, 1e-13);
            const ParamValues sp{{"T", 10.0}, {s.step_parameter, hh}};
            wp.push_back({system, name, hh, sinfo->max_error(sp, scheme, hh, Path::generic, ref),
                          sinfo->time_run(sp, scheme, hh, Path::generic, reps).median});
          }
          // the long horizon of the symmetric scheme on a conservative system: the base's energy along the discrete
          // solution (the knife edge without its damping: the constrained case)
          const double hh = system == "pendulum" ? 0.1 : 0.05, T = 1000;
          const ParamValues free = system == "pendulum" ? ParamValues{{"T", T}} : ParamValues{{"T", T}, {"alpha", 0.0}};
          if (K == 2) {
            const auto [d, d10] = energy_error(*binfo, free, scheme, hh);
            energy.push_back({system, scheme, hh, T, d, d10});
          }
          ParamValues sfree = free;
          sfree.emplace_back(s.step_parameter, hh);
          const auto [d, d10] = energy_error(*sinfo, sfree, scheme, hh);
          energy.push_back({system, name, hh, T, d, d10});
        }
      }
      for (const auto& p : wp)
        std::printf("%-11s %-26s %-8g error %10.3e  %10.3e s\n", p.system.c_str(), p.method.c_str(), p.knob, p.error, p.seconds);
      // The damping law of the first-order scheme on the paper's oscillator (q'' + alpha q' + q = 0, alpha = 0.1):
      // E_j against the closed form's E(t_j) over T = 200, the base (la) and its surrogates K = 1, 2.
      {
        const auto base = base_model(systems_dir, "oscillator");
        const auto binfo = formula::formula_system_info(base);
        const double alpha = 0.1, q0 = -0.25, v0 = 0.75, T = 200, w = std::sqrt(1 - alpha * alpha / 4);
        auto exact_energy = [&](double t) {  // q = e^{-alpha t/2}(q0 cos wt + (v0 + alpha q0/2)/w sin wt)
          const double a = q0, b = (v0 + alpha * q0 / 2) / w, e = std::exp(-alpha * t / 2);
          const double q = e * (a * std::cos(w * t) + b * std::sin(w * t));
          const double v = -alpha / 2 * q + e * (-a * w * std::sin(w * t) + b * w * std::cos(w * t));
          return (v * v + q * q) / 2;
        };
        auto law = [&](const SystemInfo& info, const ParamValues& q, const std::string& method, double hh) {
          const Run run = info.run(q, "la", hh, Path::generic, 1);
          double st = 0, sy = 0, stt = 0, sty = 0, worst = 0;
          const double n = double(run.t.size());
          for (std::size_t j = 0; j < run.t.size(); ++j) {
            const double r = run.energy[j] / exact_energy(run.t[j]);
            worst = std::max(worst, std::abs(r - 1));
            const double y = std::log(r), t = run.t[j];
            st += t, sy += y, stt += t * t, sty += t * y;
          }
          damping.push_back({method, hh, T, (n * sty - st * sy) / (n * stt - st * st), worst});
        };
        const ParamValues pv{{"T", T}, {"alpha", alpha}, {"q0", q0}, {"p0", v0}};
        for (double hh : {0.1, 0.05}) {
          law(*binfo, pv, "la", hh);
          for (int K : {1, 2}) {
            const auto s = modified::build_surrogate(base, "la", K, budget);
            const auto sinfo = formula::formula_system_info(formula::compile_model(s.description));
            ParamValues sp = pv;
            sp.emplace_back(s.step_parameter, hh);
            law(*sinfo, sp, "surrogate" + std::to_string(s.K) + ":la", hh);
          }
        }
      }
      for (const auto& e : energy)
        std::printf("%-11s %-26s h = %g, T = %g: max |E - E0| = %.3e (over the first tenth %.3e)\n", e.system.c_str(),
                    e.method.c_str(), e.h, e.T, e.drift, e.drift_tenth);
      for (const auto& d : damping)
        std::printf("oscillator  %-26s h = %g, T = %g: damping rate error %.3e, max |E/E_exact - 1| = %.3e\n",
                    d.method.c_str(), d.h, d.T, d.rate_error, d.max_relative);
    }
    const auto dir = prepare_output_dir(cli.out);
    double load[3] = {0, 0, 0};
    const int got = getloadavg(load, 3);
    TsvWriter tsv(dir / "bench_surrogate.tsv", "bench_surrogate",
                  {{"cases", join_names(cases)}, {"max_order", std::to_string(max_order)}, {"budget", format_number(budget)},
                   {"h", format_number(h)}, {"reps", std::to_string(reps)},
                   {"load_average", got == 3 ? format_number(load[0]) : "unknown"}},
                  {"system", "scheme", "K", "reached", "build_seconds", "build_cpu_seconds", "base_step_ns",
                   "surrogate_step_ns", "ratio"});
    for (const auto& r : rows)
      tsv.row(r.system, r.scheme, r.K, r.reached, r.seconds, r.cpu, r.base_ns, r.surrogate_ns, r.surrogate_ns / r.base_ns);
    const Params wp_header{{"reps", std::to_string(reps)}, {"T", "10"}, {"reference", "Boost.Odeint dopri5, tol 1e-13, on the base"},
                           {"load_average", got == 3 ? format_number(load[0]) : "unknown"}};
    if (work) {
      TsvWriter w(dir / "bench_surrogate_work_precision.tsv", "bench_surrogate", wp_header,
                  {"system", "method", "h_or_tol", "error", "cpu_seconds"});
      for (const auto& p : wp) w.row(p.system, p.method, p.knob, p.error, p.seconds);
      TsvWriter e(dir / "bench_surrogate_energy.tsv", "bench_surrogate", wp_header,
                  {"system", "method", "h", "T", "max_energy_error", "max_energy_error_first_tenth"});
      for (const auto& x : energy) e.row(x.system, x.method, x.h, x.T, x.drift, x.drift_tenth);
      TsvWriter dl(dir / "bench_surrogate_damping.tsv", "bench_surrogate",
                   {{"system", "oscillator alpha = 0.1, q0 = -0.25, v0 = 0.75"}, {"scheme", "la"},
                    {"rate_error", "least-squares slope of log(E_j / E(t_j)) in t (E the closed form's)"}},
                   {"method", "h", "T", "rate_error", "max_relative_energy_error"});
      for (const auto& x : damping) dl.row(x.method, x.h, x.T, x.rate_error, x.max_relative);
      w.commit();
      e.commit();
      dl.commit();
    }
    tsv.commit();
    return 0;
  });
}
