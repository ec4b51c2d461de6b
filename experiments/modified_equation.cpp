// The modified equation of any registered scheme on any registered system, at one point, to order K:
//   q'' = F_0 + h F_1 + ... + h^K F_K   (contact: also z' = Z_0 + h Z_1 + ...; constrained: the modified
//   multiplier mu_k and the modified constraint Phi_h = sum h^k phi_k on which the discrete solution lies),
// computed by pushing truncated power series through the scheme's own residual (geomint/modified/automatic.hpp).
//   modified_equation [--system pendulum | --system-file docs/systems/X.geomint] [--schemes la contact] [--order 4] [--t 0] [--q 0.5]
//                     [--v 0.3] [--z 0] [--alpha 0.1 and the system's other parameters, as every program] [--out out]
// Defaults: the damped pendulum at (q, q') = (0.5, 0.3), alpha = 0.1 (its default), K = 4, LA and contact.
// Writes out/modified_equation.tsv (columns system, scheme, alpha, k, component, value; component F<i> is the
// i-th component of F_k, Z the z' coefficient (for contact also the modified Herglotz Lagrangian), L the
// modified (meshed) Lagrangian of an unconstrained LA scheme, mu<c> the multiplier, phi<c> the modified
// constraint, residual
// the self-check: the largest residual coefficient that must vanish) and prints it as a table.
// With --formulas it also derives the same quantities as formulas (the engine with GiNaC coefficients; every
// parameter a symbol, the point (t, q, q', z) symbolic too) within --budget seconds per scheme, and writes
//   out/modified_equation_formulas.txt  tab-separated: system, scheme, quantity, k, text, mathematica — the
//       coefficient of h^k (k = "sum": the whole series sum_k h^k c_k); `text` is read by sympy's sympify
//       ('^' powers, which sympify's default convert_xor reads; exact rationals a/b; sin(q)), `mathematica` by
//       ToExpression (Sin[q]); the '#' header lists the symbols,
//   out/modified_equation_formulas.tex  the same as LaTeX (align* blocks; '%' header lines),
// and prints the series. A scheme whose budget runs out is written to the order it reached, and says so.
// Another system than the default pendulum writes the same files prefixed with its name
// (out/knife-edge_modified_equation.tsv, ...), so that one folder holds the tables of several systems.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "geomint/cli.hpp"
#include "geomint/error.hpp"
#include "geomint/io.hpp"
#include "geomint/formula/formula_registry.hpp"
#include "geomint/modified/automatic_registry.hpp"
#include "geomint/modified/bounded_formulas.hpp"
#include "geomint/modified/formula_modified.hpp"
#include "geomint/registry.hpp"
#include "geomint/system_cli.hpp"

using namespace geomint;
using namespace geomint::modified;

namespace {

// sum_k h^k c_k in one line, from the coefficients' printed forms (zero terms left out).
std::string series_text(const std::vector<std::string>& c, bool latex) {
  std::string s;
  for (std::size_t k = 0; k < c.size(); ++k) {
    if (c[k] == "0") continue;
    std::string h = k == 0 ? "" : (k == 1 ? "h" : (latex ? "h^{" : "h^") + std::to_string(k) + (latex ? "}" : ""));
    std::string term = k == 0 ? c[k] : (latex ? h + "\\left(" + c[k] + "\\right)" : h + "*(" + c[k] + ")");
    s += s.empty() ? term : " + " + term;
  }
  return s.empty() ? "0" : s;
}

double param_value(const SystemInfo& info, const ParamValues& pv, const std::string& name) {
  for (const auto& [k, x] : pv)
    if (k == name) return x;
  for (const auto& p : info.params)
    if (p.name == name) return p.value;
  return missing_value;
}

void write_formulas(const std::filesystem::path& dir, const std::string& prefix, const std::string& system, const std::vector<std::string>& schemes,
                    Params header, const std::vector<ModifiedFormulas>& forms) {
  const bool charted = std::any_of(forms.begin(), forms.end(), [](const ModifiedFormulas& f) { return !f.chart.empty(); });
  header.emplace_back("formulas", charted ? "the same engine with GiNaC coefficients: parameters and the point (t, q1.., the "
                                            "quasi-velocities, z) symbolic, on the constraint (rows v<i>: the map back to q')"
                                          : "the same engine with GiNaC coefficients: parameters and the point (t, q1.., v1.., z) symbolic");
  header.emplace_back("syntax", "text: define_system reads it, sympy.parse_expr with the symbols as local_dict (powers '^', exact rationals a/b); mathematica: ToExpression (capitalized names in Global`)");
  // every symbol of every scheme's formulas: t, h, z, the positions, the velocities, the quasi-velocities, then the
  // parameters
  std::vector<std::string> symbols;
  for (const auto& f : forms)
    for (const auto& n : f.symbols)
      if (std::find(symbols.begin(), symbols.end(), n) == symbols.end()) symbols.push_back(n);
  // a symbol with a value is a parameter; one without, beyond t, h, z, q, v, is a quasi-velocity (--on-constraint)
  auto parameter = [&](const std::string& n) {
    for (const auto& f : forms)
      for (const auto& v : f.values)
        if (v.first == n) return true;
    return false;
  };
  auto rank = [&](const std::string& n) {
    const bool state = n.size() > 1 && (n[0] == 'q' || n[0] == 'v') &&
                       std::all_of(n.begin() + 1, n.end(), [](char c) { return std::isdigit(static_cast<unsigned char>(c)) != 0; });
    return n == "t" ? 0 : n == "h" ? 1 : n == "z" ? 2 : state ? (n[0] == 'q' ? 3 : 4) : parameter(n) ? 6 : 5;
  };
  std::stable_sort(symbols.begin(), symbols.end(), [&](const std::string& a, const std::string& b) { return rank(a) < rank(b); });
  header.emplace_back("symbols", join_names(symbols));
  std::string values;
  for (const auto& f : forms)
    for (const auto& [name, x] : f.values)
      if (values.find(name + "=") != 0 && values.find(" " + name + "=") == std::string::npos)
        values += (values.empty() ? "" : " ") + name + "=" + format_number(x);
  header.emplace_back("symbol_values", values);
  for (std::size_t s = 0; s < schemes.size(); ++s) {
    const auto& f = forms[s];
    char line[200];
    std::snprintf(line, sizeof line, "order %d of %d in %.2f s (budget %g s), %zu nodes%s", f.K, f.K_asked, f.seconds,
                  f.budget, f.size, f.stopped ? ": stopped by the budget" : "");
    header.emplace_back("formulas " + schemes[s], f.chart.empty() ? line : line + ("; on the constraint: " + f.chart));
    if (f.stopped)
      std::fprintf(stderr, "modified_equation: the formulas of %s stopped at order %d of %d: the budget of %g s ran out\n",
                   schemes[s].c_str(), f.K, f.K_asked, f.budget);
  }
  TsvWriter txt(dir / (prefix + "modified_equation_formulas.txt"), "modified_equation", header,
                {"system", "scheme", "quantity", "k", "text", "mathematica"});
  AtomicFile tex(dir / (prefix + "modified_equation_formulas.tex"));
  std::FILE* out = tex.handle();
  std::fprintf(out, "%% program: modified_equation\n%% git: %s\n", git_revision());
  for (const auto& [k, v] : header) std::fprintf(out, "%% %s: %s\n", k.c_str(), v.c_str());
  for (std::size_t s = 0; s < schemes.size(); ++s) {
    // quantity -> its coefficients by k, in the order they first appear
    std::vector<std::string> order;
    std::map<std::string, std::vector<const FormulaRow*>> by;
    for (const auto& r : forms[s].rows) {
      if (!by.count(r.quantity)) order.push_back(r.quantity);
      by[r.quantity].push_back(&r);
      txt.row(system, schemes[s], r.quantity, r.k, r.text, r.mathematica);
    }
    std::fprintf(out, "\n%% %s, scheme %s\n\\begin{align*}\n", system.c_str(), schemes[s].c_str());
    std::printf("\n%s, %s (formulas, order %d):\n", system.c_str(), schemes[s].c_str(), forms[s].K);
    for (const auto& qn : order) {
      std::vector<std::string> text, mma, latex;
      for (const auto* r : by[qn]) {
        text.push_back(r->text);
        mma.push_back(r->mathematica);
        latex.push_back(r->latex);
      }
      txt.row(system, schemes[s], qn, "sum", series_text(text, false), series_text(mma, false));
      std::printf("  %s = %s\n", qn.c_str(), series_text(text, false).c_str());
      std::string tq = qn;
      const auto digit = tq.find_first_of("0123456789");
      if (digit != std::string::npos) tq = tq.substr(0, digit) + "_{" + tq.substr(digit) + "}";
      std::fprintf(out, "\\mathrm{%s} &= %s \\\\\n", tq.c_str(), series_text(latex, true).c_str());
    }
    std::fprintf(out, "\\end{align*}\n");
  }
  txt.commit();
  tex.commit();
}

}  // namespace

int main(int argc, char** argv) {
  return guarded_main("modified_equation", [&] {
    const std::string default_system = "pendulum";
    std::vector<std::string> schemes{"la", "contact"};
    int K = 4;
    double t = 0, z = 0;
    std::vector<double> q{0.5}, v{0.3};
    bool formulas = false, on_constraint = false;
    double budget = 60;
    Cli cli("modified_equation", "the modified equation q'' = sum_k h^k F_k of a scheme at a point, to order K");
    // --system or --system-file, and the system's parameters as options of their own (--alpha 0.2), as every program
    const SystemOptions sys_opts(cli, argc, argv, default_system, false);
    cli.options.add_options()("schemes", po::value(&schemes)->multitoken()->default_value(schemes, "la contact"),
                              "schemes (see --help --system X)")(
        "order", po::value(&K)->default_value(K), "order K (0..6)")("t", po::value(&t)->default_value(t), "time")(
        "q", po::value(&q)->multitoken()->default_value(q, "0.5"), "position (n components)")(
        "v", po::value(&v)->multitoken()->default_value(v, "0.3"), "velocity q' (n components)")(
        "z", po::value(&z)->default_value(z), "Herglotz action z (contact schemes)")(
        "formulas", po::bool_switch(&formulas), "also derive the modified equation as formulas (text, Mathematica, LaTeX)")(
        "on-constraint", po::bool_switch(&on_constraint),
        "formulas on the nonholonomic constraint: in quasi-velocities (q' = S(q) u + w, the rows v<i> the map back), "
        "smaller and found sooner")(
        "budget", po::value(&budget)->default_value(budget), "time budget of the formulas, seconds per scheme");
    if (!cli.parse(argc, argv)) return 0;

    // A system file's entry holds its model: the modified equations of its shape, alive to the end.
    const auto& info = sys_opts.system();
    const std::string& system_file = sys_opts.system_file();
    const std::string system = info.name;
    const auto me = modified_system(info);
    const ModifiedSystem& ms = *me;
    if (on_constraint) {
      require(formulas, "--on-constraint is a form of the formulas: give --formulas with it");
      require(info.constraints > 0 && !ms.holonomic,
              "--on-constraint: system '" + system + "' has no nonholonomic constraint to chart");
    }
    const ParamValues pv = sys_opts.values();
    require(K >= 0 && K <= registry_max_order, "order must be in [0, " + std::to_string(registry_max_order) + "], got " + std::to_string(K));
    require(std::isfinite(t) && std::isfinite(z), "t and z must be finite");
    for (double x : q) require_finite(x, "q");
    for (double x : v) require_finite(x, "v");
    require(static_cast<int>(q.size()) == info.dof && static_cast<int>(v.size()) == info.dof,
            "system '" + system + "' has " + std::to_string(info.dof) + " degrees of freedom: give that many --q and --v values");
    for (const auto& s : schemes) {
      if (formulas)
        formula_scheme(info, s);
      else
        modified_scheme(info, s);
    }
    require(std::isfinite(budget) && budget > 0, "--budget must be a positive number of seconds");
    sys_opts.warn_contact({pv}, schemes);

    // Compute everything before writing anything.
    std::vector<ModifiedPoint> points;
    for (const auto& s : schemes) points.push_back(ms.at(pv, s, K, t, q, v, z, true));
    std::vector<ModifiedFormulas> forms;
    if (formulas)
      for (const auto& s : schemes) forms.push_back(bounded_formulas(ms, pv, s, K, budget, on_constraint));  // the budget holds inside an order

    const auto dir = prepare_output_dir(cli.out);
    Params header = info.header(pv);
    if (!system_file.empty()) header.insert(header.begin() + 1, {"system_file", system_file});
    header.insert(header.end(), {{"schemes", join_names(schemes)},
                                 {"order", std::to_string(K)},
                                 {"t", format_number(t)},
                                 {"q", format_list(q)},
                                 {"v", format_list(v)},
                                 {"z", format_number(z)},
                                 {"method", "series in (time, h) pushed through the scheme's residual; one solve per order"}});
    const std::string prefix = system == default_system ? "" : system + "_";
    TsvWriter tsv(dir / (prefix + "modified_equation.tsv"), "modified_equation", header,
                  {"system", "scheme", "alpha", "k", "component", "value"});
    const double alpha = param_value(info, pv, "alpha");
    std::printf("%s at t = %g, q = %s, q' = %s, z = %g (alpha = %g)\n", system.c_str(), t, format_list(q).c_str(),
                format_list(v).c_str(), z, alpha);
    std::printf("%-18s %-3s %-10s %24s\n", "scheme", "k", "component", "value");
    for (std::size_t s = 0; s < schemes.size(); ++s) {
      const auto& P = points[s];
      auto emit = [&](int k, const std::string& comp, double value) {
        tsv.row(system, schemes[s], alpha, k, comp, value);
        std::printf("%-18s %-3d %-10s %24.16e\n", schemes[s].c_str(), k, comp.c_str(), value);
      };
      for (int k = 0; k <= K; ++k) {
        for (int i = 0; i < P.n; ++i) emit(k, "F" + std::to_string(i), P.F_at(k, i));
        if (P.contact) emit(k, "Z", P.Z[static_cast<std::size_t>(k)]);
        if (!P.contact && P.m == 0) emit(k, "L", P.lagrangian[static_cast<std::size_t>(k)]);
        for (int c = 0; c < P.m; ++c) emit(k, "mu" + std::to_string(c), P.mu[static_cast<std::size_t>(k * P.m + c)]);
      }
      for (int c = 0; c < P.m; ++c)
        for (std::size_t k = 0; k * static_cast<std::size_t>(P.m) + static_cast<std::size_t>(c) < P.phi.size(); ++k)
          emit(static_cast<int>(k), "phi" + std::to_string(c), P.phi[k * static_cast<std::size_t>(P.m) + static_cast<std::size_t>(c)]);
      emit(K, "residual", P.residual);
    }
    tsv.commit();
    if (formulas) write_formulas(dir, prefix, system, schemes, header, forms);
    return 0;
  });
}
