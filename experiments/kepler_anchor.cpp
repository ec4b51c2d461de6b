// The contact-integrator literature's comparison on the time-perturbed Kepler problem (Bravetti, Seri, Vermeeren,
// Zadra 2020; geomint/kepler_anchor.hpp says what they measured and how), redone with geomint's schemes: second-
// and sixth-order contact (contact-trapezoid and its yoshida6a composition) and their Lagrange–d'Alembert twins
// against Odeint's fixed-step RK4, every error against a tight Odeint reference, plus the exact angular-momentum law.
//   kepler_anchor [--settings anchor-1 anchor-2 error-e0 error-e0.2 error-e0.5] [--methods ...] [--tau t] [--T T]
//                 [--tol 1e-13] [--reps 3] [--out out]
// Writes out/kepler_anchor.tsv (every kept step: t, q, the errors), out/kepler_anchor_summary.tsv (maxima per
// setting and method), out/kepler_anchor_timings.tsv (CPU seconds per run; apart, as timings are not reproducible
// bit for bit) and a figure per setting (trajectory, energy error, position error) drawn from the first file.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

#include "geomint/budget.hpp"
#include "geomint/cli.hpp"
#include "geomint/error.hpp"
#include "geomint/io.hpp"
#include "geomint/kepler_anchor.hpp"
#include "geomint/plots/figure.hpp"

using namespace geomint;

int main(int argc, char** argv) {
  return guarded_main("kepler_anchor", [&] {
    Cli cli("kepler_anchor", "the contact-integrator anchor's comparison on the perturbed Kepler problem");
    std::vector<std::string> setting_names, methods = kepler_anchor_methods();
    double tau = 0, T = 0, tol = 1e-13;
    bool tau_given = false, T_given = false;  // a given value is checked, whatever it is (nan included)
    int reps = 3;
    std::string all_names;
    for (const auto& s : kepler_anchor_settings()) all_names += (all_names.empty() ? "" : " ") + s.name;
    cli.options.add_options()("settings", po::value(&setting_names)->multitoken(), ("settings to run (default: all of " + all_names + ")").c_str())(
        "methods", po::value(&methods)->multitoken(),
        "schemes of the kepler system, compositions <family>:<scheme>, or odeint-rk4 (default: contact-trapezoid "
        "yoshida6a:contact-trapezoid odeint-rk4 la-trapezoid yoshida6a:la-trapezoid)")(
        "tau", po::value(&tau)->notifier([&](double) { tau_given = true; }), "step size for every setting (default: each setting's own, 0.5 or 0.05)")(
        "T", po::value(&T)->notifier([&](double) { T_given = true; }), "horizon for every setting (default: each setting's own)")(
        "tol", po::value(&tol)->default_value(tol, "1e-13"), "tolerance of the Odeint reference")(
        "reps", po::value(&reps)->default_value(reps), "timing repetitions per run (0: no timings)");
    if (!cli.parse(argc, argv)) return 0;
    require(!methods.empty(), "--methods needs at least one method");
    require(reps >= 0 && reps <= 1000, "reps must be in [0, 1000]");
    std::vector<KeplerSetting> settings;
    for (const auto& s : kepler_anchor_settings())
      if (setting_names.empty() || std::find(setting_names.begin(), setting_names.end(), s.name) != setting_names.end())
        settings.push_back(s);
    for (const auto& n : setting_names) {
      bool known = false;
      for (const auto& s : settings) known = known || s.name == n;
      require(known, "unknown setting '" + n + "' (known: " + all_names + ")");
    }
    if (tau_given) require_positive(tau, "tau");
    if (T_given) require_positive(T, "T");
    for (auto& s : settings) {
      if (tau_given) s.tau = tau;
      if (T_given) s.T = T;
      // every run, the reference (twice) and the timings: the work before it starts
      const double steps = static_cast<double>(step_count(s.tau, s.T));
      plan_steps(steps * static_cast<double>(methods.size() + 2) * (1 + reps), "kepler_anchor " + s.name);
      // held at once: the output times, the two references (4 numbers a time) and, per method, its trajectory
      // (5) and the run it is read from (up to 13)
      check_memory((steps + 1) * sizeof(double) * (9 + 18 * static_cast<double>(methods.size())),
                   "kepler_anchor " + s.name + " (lower --T or raise --tau)");
    }
    const auto dir = prepare_output_dir(cli.out);

    const KeplerAnchor res = kepler_anchor(settings, methods, tol);
    for (const auto& sc : res.scores)
      if (!sc.failure.empty())
        std::fprintf(stderr, "kepler_anchor: %s %s: %s (recorded as a missing value)\n", sc.setting.c_str(), sc.method.c_str(),
                     sc.failure.c_str());

    std::string setting_list, method_list;
    for (const auto& s : settings)
      setting_list += (setting_list.empty() ? "" : "; ") + s.name + ": a " + format_number(s.a) + ", theta " +
                      format_number(s.theta) + ", e " + format_number(s.e) + ", T " + format_number(s.T) + ", tau " +
                      format_number(s.tau);
    for (const auto& m : methods) method_list += (method_list.empty() ? "" : " ") + m;
    const Params params{{"system", "kepler (alpha 0)"},
                        {"settings", setting_list},
                        {"methods", method_list},
                        {"reference", res.reference},
                        {"energy", "E = |p|^2/2 - 1/|q| (the anchor's contact Hamiltonian error: its f(t) term cancels)"},
                        {"momentum", "M = q x p against M(0) exp(-a/theta (1 - cos theta t))"}};
    const std::map<std::string, const KeplerSetting*> by_name = [&] {
      std::map<std::string, const KeplerSetting*> m;
      for (const auto& s : settings) m[s.name] = &s;
      return m;
    }();

    TsvWriter traces(dir / "kepler_anchor.tsv", "kepler_anchor", params,
                     {"setting", "method", "t", "q1", "q2", "q1_ref", "q2_ref", "energy_err", "position_err", "momentum_err"});
    for (const auto& tr : res.traces)
      for (std::size_t k = 0; k < tr.t.size(); ++k)
        traces.row(tr.setting, tr.method, tr.t[k], tr.q1[k], tr.q2[k], tr.q1_ref[k], tr.q2_ref[k], tr.energy_err[k],
                   tr.position_err[k], tr.momentum_err[k]);
    traces.commit();

    TsvWriter summary(dir / "kepler_anchor_summary.tsv", "kepler_anchor", params,
                      {"setting", "a", "theta", "e", "T", "tau", "method", "order", "max_energy_err", "max_position_err",
                       "final_position_err", "max_momentum_err", "diff_to_sixth", "work_per_step", "work_unit",
                       "reference_err"});
    std::printf("%-11s %-30s %5s %12s %12s %12s %12s %12s %8s\n", "setting", "method", "order", "max |dE|", "max |dq|",
                "|dq(T)|", "max |dM/M|", "|q - q_6th|", "work");
    for (const auto& sc : res.scores) {
      const KeplerSetting& s = *by_name.at(sc.setting);
      summary.row(sc.setting, s.a, s.theta, s.e, s.T, s.tau, sc.method, sc.order, sc.max_energy_err, sc.max_position_err,
                  sc.final_position_err, sc.max_momentum_err, sc.diff_to_sixth, sc.work_per_step,
                  sc.work_unit.empty() ? std::string("-") : sc.work_unit, sc.reference_err);
      std::printf("%-11s %-30s %5d %12.3e %12.3e %12.3e %12.3e %12.3e %5.2f %s\n", sc.setting.c_str(), sc.method.c_str(),
                  sc.order, sc.max_energy_err, sc.max_position_err, sc.final_position_err, sc.max_momentum_err,
                  sc.diff_to_sixth, sc.work_per_step, sc.work_unit.c_str());
    }
    summary.commit();

    if (reps > 0) {
      TsvWriter timings(dir / "kepler_anchor_timings.tsv", "kepler_anchor", params,
                        {"setting", "method", "seconds_per_run", "reps"});
      std::printf("\nCPU seconds per run (median of %d):\n", reps);
      for (const auto& s : settings)
        for (const auto& m : methods) {
          double sec = missing_value;
          try {
            sec = kepler_anchor_seconds(s, m, reps);
          } catch (const NumericalFailure&) {
            // already reported above as a missing value
          }
          timings.row(s.name, m, sec, reps);
          std::printf("%-11s %-30s %12.3e\n", s.name.c_str(), m.c_str(), sec);
        }
      timings.commit();
    }

    // One figure per setting, from the saved trace table: the orbits (the reference in black; a run that leaves
    // the frame has left the orbit), the anchor's energy error, the position error.
    const auto t = plots::read_tsv(output_path_for_reading(dir / "kepler_anchor.tsv"));
    for (const auto& s : settings) {
      char title[256];
      std::snprintf(title, sizeof title, "perturbed Kepler, %s: a = %g, theta = %.4g, e = %g, tau = %g, T = %g", s.name.c_str(),
                    s.a, s.theta, s.e, s.tau, s.T);
      plots::Figure fig;
      fig.title = title;
      fig.cols = 3;
      fig.width_in = 13;
      fig.height_in = 4.2;
      plots::Panel orbit, energy, position;
      orbit.setup = "set size ratio -1\nset xrange [-2.5:2.5]\nset yrange [-2.5:2.5]\nset xlabel 'q_1'\nset ylabel 'q_2'\nset key off\n";
      energy.setup = "set logscale y\nset format y '10^{%L}'\nset xlabel 't'\nset ylabel '|E - E_{ref}|'\nset key off\n";
      position.setup = "set logscale y\nset format y '10^{%L}'\nset xlabel 't'\nset ylabel '|q - q_{ref}|'\n"
                       "set key outside right font ',7'\n";
      bool reference = false;
      for (const auto& m : methods) {
        auto keep = [&](std::size_t r) { return t.text(r, "setting") == s.name && t.text(r, "method") == m; };
        const auto times = t.numbers("t", keep);
        if (times.empty()) continue;  // the method failed in this setting
        if (!reference) {
          orbit.series.push_back({t.numbers("q1_ref", keep), t.numbers("q2_ref", keep), "reference", plots::style_for("reference")});
          reference = true;
        }
        const std::string style = plots::style_for(m, "lines");
        orbit.series.push_back({t.numbers("q1", keep), t.numbers("q2", keep), m, style});
        energy.series.push_back({times, t.numbers("energy_err", keep), m, style});
        position.series.push_back({times, t.numbers("position_err", keep), m, style});
      }
      fig.panels = {orbit, energy, position};
      fig.draw(dir / ("kepler_anchor_" + s.name));
    }
    return 0;
  });
}
