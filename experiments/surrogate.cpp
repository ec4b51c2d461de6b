// Surrogate systems: higher order from a low-order scheme by changing the system (modified/surrogate.hpp). For a
// system given by its formulas and each scheme, the engine builds the surrogate data to order K — the Lagrangian
// and force corrections (LA), the Herglotz Lagrangian's (contact), the constraint rows' (where linear in the
// velocities), the consistent initial velocity — certifies it (orders 1..K of the surrogate's own modified
// equation vanish as formulas; in numbers its defect falls like h^(K+1)), and writes it as a system file that every
// program runs (--system-file, with its parameter --step equal to the step the run takes).
//   surrogate [--system-file docs/systems/oscillator.geomint] [--schemes la contact] [--order 2] [--step 0.1]
//             [--budget 120] [--out out]
// Writes, for system X (the file's name):
//   out/X_surrogate_formulas.txt  tab-separated: system, scheme, quantity (L, F<i>, herglotz, phi<c>, v<i>), k, text,
//       mathematica — the correction at h^k (text: sympy's sympify; mathematica: ToExpression); the '#' header has
//       each scheme's certification,
//   out/X_surrogate_formulas.tex  the same as LaTeX,
//   out/X_surrogate_certification.tsv  scheme, K, k, symbolic (1: order k of the surrogate's modified equation is 0
//       as a formula), leading (the first order beyond K that is not), and the numeric defect against h,
//   out/X-surrogate-<scheme>-<K>.geomint  each surrogate as a system file,
// and prints what it built. Every output is written together after everything is computed.
#include <cstdio>
#include <string>
#include <vector>

#include "geomint/cli.hpp"
#include "geomint/error.hpp"
#include "geomint/formula/model.hpp"
#include "geomint/io.hpp"
#include "geomint/modified/surrogate.hpp"
#include "geomint/system_cli.hpp"

using namespace geomint;

int main(int argc, char** argv) {
  return guarded_main("surrogate", [&] {
    std::string file;
    std::vector<std::string> schemes{"la", "contact"};
    int K = 2;
    double step = 0.1, budget = 120;
    Cli cli("surrogate", "surrogate systems: the scheme on them follows the system's equations to O(h^(K+1))");
    cli.options.add_options()("system-file", po::value(&file), "the system, as a system file (docs/systems/README.md); default: the paper's oscillator")(
        "schemes", po::value(&schemes)->multitoken()->default_value(schemes, "la contact"),
        "schemes: la, contact, la-midpoint, la-trapezoid, contact-trapezoid")(
        "order", po::value(&K)->default_value(K), "order K of the surrogate (1..5)")(
        "step", po::value(&step)->default_value(step, "0.1"), "the default of the surrogate's step parameter (step) in its file")(
        "budget", po::value(&budget)->default_value(budget), "time budget, seconds per scheme");
    if (!cli.parse(argc, argv)) return 0;
    (void)find_system_file_arg(argc, argv);  // refuses --system-file "", which would read as the default system

    require(K >= 1 && K <= 5, "--order must be an integer in [1, 5]");
    require(std::isfinite(step) && step > 0, "--step must be a positive number");
    require(std::isfinite(budget) && budget > 0, "--budget must be a positive number of seconds");
    // without --system-file, the paper's damped oscillator (Section 3.1), as docs/systems/oscillator.geomint has it
    const auto base = file.empty() ? formula::compile_model(formula::parse_system_file(R"(
[system]
name = oscillator
description = damped harmonic oscillator (Section 3.1): q'' + alpha q' + q = 0
coordinates = 1
[parameters]
alpha = 0.01   # Rayleigh damping
q0 = -0.25     # initial position
p0 = 0.75      # initial momentum (= velocity)
T = 50         # horizon
[dynamics]
L = v1*v1/2 - q1*q1/2
herglotz = L - alpha*z
F1 = -alpha*v1
[initial]
q1 = q0
v1 = p0
)", "the paper's oscillator"))
                                   : formula::load_system_file(file);

    std::vector<modified::SurrogateSystem> built;
    for (const auto& s : schemes) built.push_back(modified::build_surrogate(base, s, K, budget, step));

    const auto dir = prepare_output_dir(cli.out);
    Params header{{"system", base->name}, {"system_file", file.empty() ? "(the paper's oscillator)" : file},        {"schemes", join_names(schemes)},
                  {"order", std::to_string(K)}, {"step", format_number(step)}, {"budget", format_number(budget)},
                  {"method", "the modified-equation engine run on the surrogate itself, one correction per order"}};
    for (const auto& s : built) {
      char line[400];
      std::snprintf(line, sizeof line, "order %d of %d in %.2f s%s%s; force-free %s; defect slope %.2f", s.K, s.K_asked,
                    s.seconds, s.stopped ? " (stopped by the budget)" : "", s.why_short.empty() ? "" : " (stopped short)",
                    s.force_free ? "yes" : "no", s.defect_slope);
      header.emplace_back("surrogate " + s.scheme, line);
      if (!s.why_short.empty()) header.emplace_back("short " + s.scheme, s.why_short);
    }
    const std::string prefix = base->name + "_";
    TsvWriter txt(dir / (prefix + "surrogate_formulas.txt"), "surrogate", header,
                  {"system", "scheme", "quantity", "k", "text", "mathematica"});
    TsvWriter cert(dir / (prefix + "surrogate_certification.tsv"), "surrogate", header,
                   {"system", "scheme", "K", "row", "k_or_h", "value", "leading"});
    AtomicFile tex(dir / (prefix + "surrogate_formulas.tex"));
    std::FILE* out = tex.handle();
    std::fprintf(out, "%% program: surrogate\n%% git: %s\n", git_revision());
    for (const auto& [k, v] : header) std::fprintf(out, "%% %s: %s\n", k.c_str(), v.c_str());
    std::vector<std::unique_ptr<AtomicFile>> files;
    for (const auto& s : built) {
      std::printf("\n%s, %s: surrogate to order %d (asked %d) in %.1f s%s\n", base->name.c_str(), s.scheme.c_str(), s.K,
                  s.K_asked, s.seconds, s.force_free ? "" : ", with a force");
      if (!s.why_short.empty()) std::printf("  stopped short: %s\n", s.why_short.c_str());
      std::fprintf(out, "\n%% %s, scheme %s, order %d\n\\begin{align*}\n", base->name.c_str(), s.scheme.c_str(), s.K);
      for (const auto& t : s.terms) {
        txt.row(base->name, s.scheme, t.quantity, t.k, t.text, t.mathematica);
        std::printf("  %s_%d = %s\n", t.quantity.c_str(), t.k, t.text.c_str());
        std::fprintf(out, "\\mathrm{%s}_{%d} &= %s \\\\\n", t.quantity.c_str(), t.k, t.latex.c_str());
      }
      std::fprintf(out, "\\end{align*}\n");
      for (const auto& c : s.checks) {
        cert.row(base->name, s.scheme, s.K, "symbolic", c.k, c.symbolic_zero ? 1 : 0, c.leading.empty() ? "-" : c.leading);
        std::printf("  order %d of its modified equation: %s\n", c.k, c.symbolic_zero ? "0" : c.leading.c_str());
      }
      for (std::size_t i = 0; i < s.defect.size(); ++i)
        cert.row(base->name, s.scheme, s.K, "defect", s.defect_h[i], s.defect[i], "-");
      std::printf("  defect in numbers: slope %.2f (h0 = %g .. %g)\n", s.defect_slope, s.defect_h.front(), s.defect_h.back());
      auto f = std::make_unique<AtomicFile>(dir / (s.description.name + ".geomint"));
      std::fprintf(f->handle(), "# program: surrogate\n# git: %s\n%s", git_revision(), s.file_text.c_str());
      std::printf("  system file: %s\n", (dir / (s.description.name + ".geomint")).c_str());
      files.push_back(std::move(f));
    }
    txt.commit();
    cert.commit();
    tex.commit();
    for (auto& f : files) f->commit();
    return 0;
  });
}
