// The error measure of the paper's Figure 1 and of the contact-integrator literature, for any system:
// max_j |(shift + q_j) / (shift + q_ref(t_j)) - 1| (first component), at one h, over a sweep of parameters, against
// the closed form or, as the paper's Figure 1 does, against a scheme of the system run at h/ref-factor.
//   regularized_error --system forced-oscillator --alpha 0.01 0.1 1 2 [--h 0.1] [--shift 10] [--schemes ...]
//                     [--reference exact | <scheme>] [--ref-factor 10] [--trajectory]
// The paper's Figure 1 (the oscillator, T = 50, alpha 0.01 and 0.1, la, (7) as printed and contact against the
// leapfrog at h/10) and the forced oscillator in the literature's setting are lines of the Makefile's FIGURE_COMMANDS.
// Writes out/<system>_regularized_error.tsv (columns system, scheme, <swept parameters>, h, max_rel_err, max_abs_err
// against the reference, and max_abs_err_exact against the closed form where the reference is a scheme) and a figure
// of the error against the swept parameter; with --trajectory also every step, <system>_regularized_error_trajectory.tsv
// (the reference's rows first, as scheme "<reference>-ref"), and the figure of q and the error against t, one column
// per parameter set (the paper's Figure 1).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>

#include "geomint/budget.hpp"
#include "geomint/cli.hpp"
#include "geomint/error.hpp"
#include "geomint/io.hpp"
#include "geomint/plots/figure.hpp"
#include "geomint/record.hpp"
#include "geomint/system_cli.hpp"
#include "geomint/step_cost.hpp"

using namespace geomint;

namespace {

// A scheme's run at h/factor as a reference on its own grid (what max_error and max_relative_error read).
Reference scheme_reference(const Run& r, const std::string& scheme, int factor, double h) {
  Reference ref;
  ref.kind = scheme + " at h/" + std::to_string(factor);
  ref.h = h / factor;
  ref.N = r.steps;
  ref.n = r.n;
  ref.q = r.q;
  ref.v = r.v;
  return ref;
}

// The exact solution on t_j = j h, where double precision holds it; NumericalFailure naming the first time where
// it does not (at a damping of 1e200 it is 0 * inf).
Reference exact_reference(const SystemInfo& sys, const ParamValues& pv, double h, long N) {
  Reference e = sys.reference(pv, h, N, ReferenceKind::exact, 0);
  for (std::size_t j = 0; j < e.q.size(); ++j)
    if (!std::isfinite(e.q[j]))
      throw NumericalFailure(static_cast<long>(j) / e.n, "reference",
                             "the exact solution is not finite at t = " + show(static_cast<double>(j / static_cast<std::size_t>(e.n)) * h));
  return e;
}

}  // namespace

int main(int argc, char** argv) {
  return guarded_main("regularized_error", [&] {
    Cli cli("regularized_error", "max regularized relative error against the closed form or a finer run, over a parameter sweep");
    SystemOptions sysopt(cli, argc, argv, "forced-oscillator", true);
    double h = 0.1, shift = 10;
    int ref_factor = 10;
    bool trajectory = false;
    std::vector<std::string> names;
    std::string path_name = "fast", reference = "exact";
    cli.options.add_options()("h", po::value(&h)->default_value(h, "0.1"), "step size")(
        "shift", po::value(&shift)->default_value(shift, "10"), "the shift s in |(s + q)/(s + q_ref) - 1|")(
        "schemes", po::value(&names)->multitoken(), "schemes (default: every scheme of the system)")(
        "reference", po::value(&reference)->default_value(reference),
        "exact (the closed form) or a scheme of the system, run at h/ref-factor (the paper's Figure 1: leapfrog)")(
        "ref-factor", po::value(&ref_factor)->default_value(ref_factor), "a scheme reference runs at h/ref-factor")(
        "trajectory", po::bool_switch(&trajectory), "also write every step and draw q and the error against t")(
        "path", po::value(&path_name)->default_value(path_name), "fast (closed forms where they exist) or generic");
    if (!cli.parse(argc, argv)) return 0;
    const SystemInfo& sys = sysopt.system();
    const bool exact = reference == "exact";
    require(!exact || sys.has_exact, "system '" + sys.name + "' has no closed-form solution to measure against "
                                     "(give --reference <scheme>)");
    if (!exact) sys.scheme(reference);  // an unknown name fails here, naming the known ones
    require(ref_factor >= 1 && ref_factor <= 1000, "ref-factor must be an integer in [1, 1000], got " + std::to_string(ref_factor));
    if (exact) ref_factor = 1;
    require_positive(h, "h");
    require(std::isfinite(shift), "shift must be finite, got " + show(shift));
    const auto combos = sysopt.combinations();
    const auto swept = sysopt.swept();
    const auto schemes = sysopt.schemes(names);
    sysopt.warn_contact(combos, schemes);
    const Path path = parse_path(path_name);
    const int n = sys.dof;
    double cost = 1;  // of one step of every scheme and of the reference (at ref-factor steps a step), in cheap steps
    for (const auto& s : schemes) cost += step_cost(sys, s, path);
    if (!exact) cost += ref_factor * step_cost(sys, reference, path);
    for (const auto& pv : combos) {
      const long N = step_count(h, sys.horizon(pv));
      if (exact || sys.has_exact) check_reference_memory(sys, ReferenceKind::exact, N);
      if (!exact) {  // the reference run is stored whole, and with --trajectory every scheme's run
        check_steps(static_cast<double>(N) * ref_factor, "the reference run (T/h times ref-factor)");
        check_memory(static_cast<double>(N) * ref_factor * Run::bytes_per_step(n, sys.constraints), "the reference run");
      }
      if (trajectory) check_memory(static_cast<double>(N) * Run::bytes_per_step(n, sys.constraints), "a stored run");
      plan_steps(static_cast<double>(N), "the sweep (schemes and the reference x T/h per parameter set)", cost);
    }
    const auto dir = prepare_output_dir(cli.out);
    const std::string stem = sys.name + "_regularized_error";
    const std::string ref_name = exact ? "the closed form" : reference + " at h/" + std::to_string(ref_factor);
    const bool vs_exact = !exact && sys.has_exact;  // a scheme reference, and the closed form beside it

    Params params = sysopt.header();
    params.insert(params.end(), {{"h", format_number(h)}, {"shift", format_number(shift)}, {"path", to_string(path)},
                                 {"reference", ref_name},
                                 {"error", "max_j |(shift + q_j)/(shift + q_ref(t_j)) - 1|, first component"}});
    std::vector<std::string> cols{"system", "scheme"};
    cols.insert(cols.end(), swept.begin(), swept.end());
    cols.insert(cols.end(), {"h", "max_rel_err", "max_abs_err"});
    if (vs_exact) cols.push_back("max_abs_err_exact");
    TsvWriter tsv(dir / (stem + ".tsv"), "regularized_error", params, cols);
    std::optional<TsvWriter> traj;
    if (trajectory) {
      std::vector<std::string> tcols{"system", "scheme"};
      tcols.insert(tcols.end(), swept.begin(), swept.end());
      tcols.insert(tcols.end(), {"t", "q", "p", "q_ref", "rel_err"});
      if (sys.has_exact) tcols.push_back("abs_err_exact");
      traj.emplace(dir / (stem + "_trajectory.tsv"), "regularized_error", params, tcols);
    }
    std::printf("%-20s", "scheme");
    for (const auto& pv : combos) {
      std::string label;
      for (const auto& s : swept) label += (label.empty() ? "" : ",") + s + "=" + format_number(param_value(pv, sys, s));
      std::printf(" %14s", label.c_str());
    }
    std::printf("\n");
    // One parameter set at a time: its reference (and closed form) on T/h + 1 times is the largest thing this
    // program holds, and the memory checks above are per parameter set.
    const std::size_t M = vs_exact ? 3 : 2;
    std::vector<std::vector<std::vector<double>>> err(schemes.size(), std::vector<std::vector<double>>(combos.size()));
    for (std::size_t c = 0; c < combos.size(); ++c) {
      const ParamValues& pv = combos[c];
      const long N = step_count(h, sys.horizon(pv));
      std::vector<std::string> key;
      for (const auto& x : swept) key.push_back(format_number(param_value(pv, sys, x)));
      std::string where;
      for (const auto& [k, v] : pv) where += " " + k + "=" + show(v);
      const Run ref_run = exact ? Run{} : sys.run(pv, reference, h / ref_factor, path, 1);
      const Reference ref = exact ? exact_reference(sys, pv, h, N) : scheme_reference(ref_run, reference, ref_factor, h);
      // the closed form beside a scheme reference, where double precision holds it (else missing)
      std::optional<Reference> closed;
      if (exact)
        closed = ref;
      else if (sys.has_exact)
        closed = run_or_missing(
            "the exact solution" + where, [&] { return std::optional<Reference>(exact_reference(sys, pv, h, N)); },
            [] { return std::optional<Reference>(); });
      auto q_ref = [&](long j) { return ref.q[static_cast<std::size_t>(ref.index(j, h) * n)]; };
      auto q_exact = [&](long j) { return closed ? closed->q[static_cast<std::size_t>(j * n)] : missing_value; };
      auto row = [&](const std::string& scheme) {
        std::vector<std::string> r{sys.name, scheme};
        r.insert(r.end(), key.begin(), key.end());
        return r;
      };
      if (traj && !exact)
        for (long j = 0; j <= N; ++j) {
          const auto k = static_cast<std::size_t>(ref.index(j, h));
          auto r = row(reference + "-ref");
          r.insert(r.end(), {format_number(ref_run.t[k]), format_cell(ref_run.q[k * n]), format_cell(ref_run.p[k * n]),
                             format_cell(q_ref(j)), format_cell(0.0)});
          if (sys.has_exact) r.push_back(format_cell(closed ? std::abs(q_ref(j) - q_exact(j)) : missing_value));
          traj->write_row(r);
        }
      for (std::size_t s = 0; s < schemes.size(); ++s) {
        auto& e = err[s][c];
        e.assign(M, missing_value);
        try {
          if (!traj) {
            e[0] = sys.max_relative_error(pv, schemes[s], h, path, ref, shift);
            e[1] = sys.max_error(pv, schemes[s], h, path, ref);
            if (vs_exact && closed) e[2] = sys.max_error(pv, schemes[s], h, path, *closed);
            continue;
          }
          const Run run = sys.run(pv, schemes[s], h, path, 1);
          double rel = 0, abs_ref = 0, abs_exact = 0;
          for (long j = 0; j <= N; ++j) {
            const auto k = static_cast<std::size_t>(j);
            const double q = run.q[k * n], r_j = q_ref(j);
            const double rj = std::abs((shift + q) / (shift + r_j) - 1), ex = std::abs(q - q_exact(j));
            rel = std::max(rel, rj);
            for (int i = 0; i < n; ++i)
              abs_ref = std::max(abs_ref, std::abs(run.q[k * n + i] - ref.q[static_cast<std::size_t>(ref.index(j, h) * n + i)]));
            if (closed)
              for (int i = 0; i < n; ++i) abs_exact = std::max(abs_exact, std::abs(run.q[k * n + i] - closed->q[k * n + i]));
            auto r = row(schemes[s]);
            r.insert(r.end(), {format_number(run.t[k]), format_cell(q), format_cell(run.p[k * n]), format_cell(r_j),
                               format_cell(rj)});
            if (sys.has_exact) r.push_back(format_cell(closed ? ex : missing_value));
            traj->write_row(r);
          }
          e[0] = rel;
          e[1] = abs_ref;
          if (vs_exact && closed) e[2] = abs_exact;
        } catch (const NumericalFailure& f) {  // a run that fails is a missing value (and no trajectory rows)
          std::fprintf(stderr, "regularized_error: %s%s: %s (recorded as a missing value)\n", schemes[s].c_str(),
                       where.c_str(), f.what());
          e.assign(M, missing_value);
        }
      }
    }
    for (std::size_t s = 0; s < schemes.size(); ++s) {
      std::printf("%-20s", schemes[s].c_str());
      for (std::size_t c = 0; c < combos.size(); ++c) {
        std::vector<std::string> row{sys.name, schemes[s]};
        for (const auto& x : swept) row.push_back(format_number(param_value(combos[c], sys, x)));
        row.push_back(format_number(h));
        for (double v : err[s][c]) row.push_back(format_cell(v));
        tsv.write_row(row);
        std::printf(" %14.3e", err[s][c][0]);
      }
      std::printf("\n");
    }
    tsv.commit();
    if (traj) traj->commit();

    if (swept.size() == 1) {  // error against the swept parameter, a line per scheme
      const auto t = plots::read_tsv(dir / (stem + ".tsv"));
      const std::string x = swept.front();
      bool positive = true;
      for (const auto& pv : combos) positive = positive && param_value(pv, sys, x) > 0;
      plots::Figure fig;
      fig.title = sys.name + ": max regularized relative error (shift " + format_number(shift) + "), h = " + format_number(h);
      fig.width_in = 6.5;
      fig.height_in = 4.5;
      plots::Panel p;
      p.setup = std::string(positive ? "set logscale xy\n" : "set logscale y\n") + "set format y '10^{%L}'\nset xlabel '" +
                x + "'\nset ylabel 'max relative error'\nset key outside right font ',8'\n";
      for (const auto& name : schemes) {
        auto keep = [&](std::size_t r) { return t.text(r, "scheme") == name; };
        p.series.push_back({t.numbers(x, keep), t.numbers("max_rel_err", keep), name, plots::style_for(name, "linespoints")});
      }
      fig.panels.push_back(std::move(p));
      fig.draw(dir / stem);
    }
    if (traj) {  // q (top) and the error (bottom) against t, a column per parameter set: the paper's Figure 1
      const auto t = plots::read_tsv(dir / (stem + "_trajectory.tsv"));
      plots::Figure fig;
      fig.title = sys.name + ", h = " + format_number(h) + ", against " + ref_name;
      fig.rows = 2;
      fig.cols = static_cast<int>(combos.size());
      fig.width_in = 4.5 * fig.cols;
      fig.height_in = 7;
      std::vector<std::string> all = schemes;
      if (!exact) all.insert(all.begin(), reference + "-ref");
      for (int r = 0; r < 2; ++r)
        for (const auto& pv : combos) {
          std::string label;
          for (const auto& s : swept) label += (label.empty() ? "" : ", ") + s + " = " + format_number(param_value(pv, sys, s));
          plots::Panel p;
          p.setup = "set xlabel 't'\nset title '" + label + "' noenhanced\n" +
                    (r == 0 ? "set ylabel 'q'\nset key bottom right\n"
                            : "set ylabel '|(" + format_number(shift) + "+q)/(" + format_number(shift) +
                                  "+q_{ref}) - 1|'\nset logscale y\nset format y '10^{%L}'\nset key bottom right\n");
          for (const auto& name : all) {
            if (r == 1 && name == reference + "-ref") continue;
            auto keep = [&](std::size_t i) {
              if (t.text(i, "scheme") != name) return false;
              for (const auto& s : swept)
                if (t.number(i, s) != param_value(pv, sys, s)) return false;
              return true;
            };
            plots::Series s{t.numbers("t", keep), t.numbers(r == 0 ? "q" : "rel_err", keep),
                            name == reference + "-ref" ? reference + ", h/" + std::to_string(ref_factor) : name,
                            plots::style_for(name == reference + "-ref" ? "leapfrog-ref" : name)};
            if (r == 1)  // log axis: zero error (t = 0) is not a point
              for (auto& y : s.y)
                if (y <= 0) y = missing_value;
            p.series.push_back(std::move(s));
          }
          fig.panels.push_back(std::move(p));
        }
      fig.draw(dir / (stem + "_trajectory"));
    }
    return 0;
  });
}
