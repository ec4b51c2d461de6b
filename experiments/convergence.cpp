// Convergence of every scheme built from a system (or those named), against the system's reference: the
// closed form where it has one, else Boost.Odeint on the equations derived from its Lagrangian.
//   convergence --system pendulum [--schemes la contact ...] [--h-max 0.1] [--h-min 0.003] [--path fast|generic]
//               [--reference auto|exact|odeint|odeint-rhs] [--tol 1e-13] [--norm max|2] [--alpha 0.05 0.1 ...: a sweep]
// err_max = max_j |q_j - q_ref(t_j)| (max norm over the components, or with --norm 2 the Euclidean length), h halving
// from h-max to <= h-min; a system that declares measures (the Foucault pendulum's energy, plane and precession
// errors) gets a column for each.
// Writes out/<system>_convergence.tsv (one row per scheme, parameter combination and h), ..._fits.tsv
// (least-squares order per scheme and combination) and ....{png,pdf} (a panel per combination).
// The paper's settings are lines of the Makefile's FIGURE_COMMANDS (the oscillator's (7), (10); the Foucault
// pendulum's (15), (18) against the multiplier ODE at T = 4 s and 32 s).
// Under mpirun -n N the ranks share the (combination, scheme, h) runs; rank 0 writes the same files.
// With a time transformation (--time-transform, or time_transform in the system file: docs/time-transformation.md)
// the runs step in sigma and the error is taken at the physical time t = T (the state there by cubic Hermite
// interpolation in sigma) against Odeint on the physical system: out/<system>_time_transform.tsv, with the
// largest |w| = kappa |t' - g| of each run.
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "geomint/budget.hpp"
#include "geomint/cli.hpp"
#include "geomint/error.hpp"
#include "geomint/formula/description.hpp"
#include "geomint/formula/formula_registry.hpp"
#include "geomint/formula/model.hpp"
#include "geomint/formula/time_transform.hpp"
#include "geomint/io.hpp"
#include "geomint/plots/figure.hpp"
#include "geomint/study.hpp"
#include "geomint/sweep.hpp"
#include "geomint/system_cli.hpp"
#include "geomint/step_cost.hpp"
#include "text_columns.hpp"

using namespace geomint;

namespace {

// The error at the physical time t = T of each scheme and h on a time-transformed system (the runs in sigma).
int time_transform_convergence(const std::shared_ptr<const formula::FormulaModel>& model, const SystemOptions& sysopt,
                               const std::vector<ParamValues>& combos, const std::vector<std::string>& swept,
                               const std::vector<std::string>& schemes, const std::vector<double>& hs, double tol,
                               const std::string& out) {
  const auto info = formula::formula_system_info(model);
  const auto physical = formula::formula_system_info(model->physical);
  const int n = model->physical_n;
  for (const auto& s : schemes) info->scheme(s);
  const auto dir = prepare_output_dir(out);
  const std::string stem = model->name + "_time_transform";
  Params params = sysopt.header();
  params.insert(params.end(), {{"h", format_list(hs)}, {"path", "generic"}, {"tol", format_number(tol)},
                               {"error", "max_i |q_i(t = T) - q_ref,i(T)|: the state at the physical time T by cubic Hermite "
                                         "interpolation in sigma of (Q, Q') between the two steps around it (O(h^4)), the "
                                         "reference Boost.Odeint on the physical system"},
                               {"w_max", "max_j |kappa (t'_j - g_j)|: zero on the exact flow"}});
  std::vector<std::string> cols{"system", "scheme"};
  cols.insert(cols.end(), swept.begin(), swept.end());
  cols.insert(cols.end(), {"h", "steps", "sigma_end", "err_t", "order", "w_max", "order_w"});
  TsvWriter tsv(dir / (stem + ".tsv"), "convergence", params, cols);
  std::printf("%s with dt = g dsigma: error at t = T against Odeint on the physical system\n", model->name.c_str());
  for (const auto& pv : combos) {
    ParamValues phys;
    for (const auto& [k, x] : pv)
      if (model->physical->parameter_index(k) >= 0) phys.emplace_back(k, x);
    const double T = info->horizon(pv);
    const Reference ref = physical->reference(phys, T, 1, ReferenceKind::odeint, tol);
    std::vector<std::string> key;
    for (const auto& sw : swept)
      for (const auto& [k, x] : pv)
        if (k == sw) key.push_back(format_number(x));
    for (const auto& s : schemes) {
      std::vector<double> err, w;
      for (std::size_t i = 0; i < hs.size(); ++i) {
        const formula::PhysicalRun r = formula::run_to_physical_time(*info, *model, pv, s, hs[i], T, Path::generic);
        double e = 0;
        for (int c = 0; c < n; ++c)
          e = std::max(e, std::abs(r.end.q[static_cast<std::size_t>(c)] - ref.q[static_cast<std::size_t>(n + c)]));
        err.push_back(e);
        w.push_back(r.residual);
        auto local = [&](const std::vector<double>& y) {
          return i == 0 ? missing_value : std::log(y[i - 1] / y[i]) / std::log(hs[i - 1] / hs[i]);
        };
        std::vector<std::string> row{model->name, s};
        row.insert(row.end(), key.begin(), key.end());
        row.insert(row.end(), {format_cell(hs[i]), std::to_string(r.run.steps), format_cell(r.end.sigma), format_cell(e),
                               format_cell(local(err)), format_cell(r.residual), format_cell(local(w))});
        tsv.write_row(row);
      }
      const AsymptoticOrder fit = asymptotic_order(hs, err, 0.1, 1e3 * tol);
      const AsymptoticOrder fit_w = asymptotic_order(hs, w, 0.1, 1e-14);
      std::printf("  %-20s error in t: %s\n  %-20s |w|:        %s\n", s.c_str(), fit.describe().c_str(), "", fit_w.describe().c_str());
    }
  }
  tsv.commit();
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return guarded_main("convergence", [&] {
    Cli cli("convergence", "error against h of every scheme of a system, with fitted orders");
    SystemOptions sysopt(cli, argc, argv, "pendulum", true);
    double h_max = 0.1, h_min = 0.003, tol = 1e-13;
    std::vector<std::string> names;
    std::string path_name = "fast", ref_name = "auto", norm_name = "max";
    cli.options.add_options()("h-max", po::value(&h_max)->default_value(h_max, "0.1"), "largest step")(
        "h-min", po::value(&h_min)->default_value(h_min, "0.003"), "halve until h <= h-min")(
        "schemes", po::value(&names)->multitoken(), "schemes (default: every scheme of the system)")(
        "path", po::value(&path_name)->default_value(path_name), "fast (closed forms where they exist) or generic")(
        "reference", po::value(&ref_name)->default_value(ref_name),
        "auto (the exact solution if any: a closed form, or a system file's [exact] section; else odeint), exact, odeint (equations from L by AD), odeint-rhs (hand-written)")(
        "tol", po::value(&tol)->default_value(tol, "1e-13"), "Odeint tolerance of the reference")(
        "norm", po::value(&norm_name)->default_value(norm_name),
        "max (the largest component of q - q_ref) or 2 (its Euclidean length)");
    if (!cli.parse(argc, argv)) return 0;
    const SystemInfo& sys = sysopt.system();
    const auto combos = sysopt.combinations();
    const auto swept = sysopt.swept();
    const auto schemes = sysopt.schemes(names);
    sysopt.warn_contact(combos, schemes);
    if (!sysopt.system_file().empty()) {
      formula::SystemDescription d = formula::read_system_file(sysopt.system_file());
      const std::string g = find_time_transform_arg(argc, argv);
      if (!g.empty()) d.time_transform = formula::formula_text(g, "--time-transform");
      if (d.time_transform.given())
        return time_transform_convergence(formula::compile_model(d), sysopt, combos, swept, schemes,
                                          halving_sequence(h_max, h_min), tol, cli.out);
    }
    const Path path = parse_path(path_name);
    const ReferenceKind ref_kind = parse_reference(ref_name);
    const ErrorNorm norm = parse_norm(norm_name);
    check_reference(sys, ref_kind, tol);
    const auto hs = halving_sequence(h_max, h_min);
    const double h_ref = reference_step(sys, hs);
    plan_convergence(sys, combos, schemes, hs, path);
    for (const auto& pv : combos) check_reference_memory(sys, ref_kind, step_count(h_ref, sys.horizon(pv)));
    const auto dir = prepare_output_dir(cli.out, OtherRanks::compute);
    const std::string stem = sys.name + "_convergence";

    // The study (studies/include/geomint/study.hpp): every (combination, scheme, h) run, shared by the ranks under
    // mpirun; rank 0 writes.
    const Sweep& sweep = Sweep::world();
    const ConvergenceStudy study = convergence_study(sys, combos, schemes, hs, path, ref_kind, tol, sweep, norm);
    if (!sweep.root()) return 0;
    const std::size_t S = schemes.size();
    const int width = name_width(schemes, 20);
    Params params = sysopt.header();
    params.insert(params.end(), {{"h", format_list(hs)}, {"path", to_string(path)}, {"reference", ref_name},
                                 {"tol", format_number(tol)}, {"norm", to_string(norm)},
                                 {"fit_band", "errors above the reference's floor (round-off 1e-13 against a closed form, " +
                                                  format_number(reference_floor_factor) +
                                                  " x tol against Odeint) and below the solution's size max|q_ref|"},
                                 {"error", norm == ErrorNorm::max ? "max_j max_i |q_i(t_j) - q_ref,i(t_j)|"
                                                                  : "max_j |q(t_j) - q_ref(t_j)| (Euclidean)"}});
    for (const auto& m : study.measures) params.push_back({m.name, m.doc});
    std::vector<std::string> cols{"system", "scheme"};
    cols.insert(cols.end(), swept.begin(), swept.end());
    std::vector<std::string> fit_cols = cols;
    cols.insert(cols.end(), {"h", "steps", "err_max", "order"});
    for (const auto& m : study.measures) cols.push_back(m.name);
    fit_cols.insert(fit_cols.end(), {"fitted_order", "points", "expected_order"});
    TsvWriter tsv(dir / (stem + ".tsv"), "convergence", params, cols);
    TsvWriter fits(dir / (stem + "_fits.tsv"), "convergence", params, fit_cols);
    std::printf("%s, reference: %s\n", sys.name.c_str(), study.reference.c_str());
    for (std::size_t c = 0; c < combos.size(); ++c) {
      const ParamValues& pv = combos[c];
      std::vector<std::string> key;
      std::string label;
      for (const auto& sw : swept) {
        key.push_back(format_number(param_value(pv, sys, sw)));
        label += (label.empty() ? "" : ", ") + sw + " = " + key.back();
      }
      for (std::size_t si = 0; si < S; ++si) {
        const ConvergenceSeries& se = study.series[c * S + si];
        std::vector<std::string> row{sys.name, se.scheme};
        row.insert(row.end(), key.begin(), key.end());
        for (std::size_t i = 0; i < hs.size(); ++i) {
          auto r = row;
          r.insert(r.end(), {format_cell(hs[i]), std::to_string(se.steps[i]), format_cell(se.err[i]),
                             format_cell(se.local_order[i])});
          for (double x : se.measures[i]) r.push_back(format_cell(x));
          tsv.write_row(r);
        }
        auto r = row;
        r.insert(r.end(), {format_cell(se.fit.slope), std::to_string(se.fit.points), std::to_string(se.expected_order)});
        fits.write_row(r);
        char order[96];
        if (std::isfinite(se.fit.slope))
          std::snprintf(order, sizeof order, "fitted order %6.3f", se.fit.slope);
        else  // the rule's at least three points are not there: no number passed off as an order
          std::snprintf(order, sizeof order, "no fitted order (%d point%s in the band)", se.fit.points,
                        se.fit.points == 1 ? "" : "s");
        std::printf("  %-*s %-*s%s  err(h=%g) = %.3e\n    asymptotic range: %s\n", width, se.scheme.c_str(),
                    label.empty() ? 0 : 25, label.c_str(), order, hs.front(), se.err.front(), se.asymptotic.describe().c_str());
      }
    }
    tsv.commit();
    fits.commit();

    const auto t = plots::read_tsv(dir / (stem + ".tsv"));
    plots::Figure fig;
    fig.title = sys.name + ": max_j |q_j - q(t_j)| against h";
    fig.cols = static_cast<int>(std::min<std::size_t>(combos.size(), 4));
    fig.rows = static_cast<int>((combos.size() + 3) / 4);
    fig.width_in = 4.4 * fig.cols;
    fig.height_in = 4.2 * fig.rows;
    for (std::size_t c = 0; c < combos.size(); ++c) {
      const ParamValues& pv = combos[c];
      auto same = [&](std::size_t r) {
        for (const auto& s : swept)
          if (t.number(r, s) != param_value(pv, sys, s)) return false;
        return true;
      };
      std::string title;
      for (const auto& s : swept) title += (title.empty() ? "" : ", ") + s + " = " + format_number(param_value(pv, sys, s));
      plots::Panel p;
      p.setup = "set logscale xy\nset format y '10^{%L}'\nset xlabel 'h'\nset ylabel 'max error in q'\n"
                "set key bottom right font ',8'\nset title '" + (title.empty() ? sys.name : title) + "'\n";
      for (std::size_t si = 0; si < S; ++si) {
        const std::string& name = schemes[si];
        auto keep = [&](std::size_t r) { return t.text(r, "scheme") == name && same(r); };
        const auto x = t.numbers("h", keep), y = t.numbers("err_max", keep);
        p.series.push_back({x, y, plots::slope_label(name, fit_order(x, y, study.series[c * S + si].band).slope),
                            plots::style_for(name, "linespoints")});
      }
      fig.panels.push_back(std::move(p));
    }
    fig.draw(dir / stem);
    return 0;
  });
}
