// Figure 2 of the paper: the damped Foucault pendulum (Section 3.2) integrated by the LA nonholonomic
// integrator (15) and the contact nonholonomic integrator (18): energy against time (top row) and the
// bob's trajectory (bottom row), one column per alpha; plus a companion figure per further h (the paper
// says the LA anomaly disappears at h/20 = 0.005) and, per h, the plane of oscillation against its exact
// angle theta0 - Omega sin(beta) t at every turning point.
//   fig2_foucault [--h 0.1 0.005] [--alpha 1e-3 1e-4] [--T 3600] [--start legendre] [--sample-dt 2]
//                 [--system foucault] [--out out]
// --system foucault-rotation runs the remedy (the rotation discretization of (13), systems/foucault/steps.hpp)
// instead of the paper's third row of (15)/(18); its files are named fig2_foucault_rotation* so they sit next to the paper's.
// For the first h writes out/fig2_foucault.tsv (decimated samples: every sample-dt seconds and every
// turning point, plus closed-form reference rows), out/fig2_foucault_summary.tsv (one row per scheme and
// alpha), out/fig2_foucault.{png,pdf} and out/fig2_foucault_plane.{png,pdf}, all drawn from the TSV;
// each further h writes the same set under fig2_foucault_h<h>.
// Energy is the chord energy E_{j+1/2} = m/2 |(q_{j+1}-q_j)/h|^2 + m w2/2 |(q_j+q_{j+1})/2|^2 at t_j + h/2.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

#include "geomint/constants.hpp"
#include "geomint/budget.hpp"
#include "geomint/cli.hpp"
#include "geomint/scene_options.hpp"
#include "geomint/error.hpp"
#include "geomint/foucault_diagnostics.hpp"
#include "geomint/observers.hpp"
#include "geomint/io.hpp"
#include "geomint/plots/figure.hpp"

using namespace geomint;

namespace {

constexpr double deg = 180 / geomint::pi;

// One step of run_foucault (the closed form of (15)/(18) with its chord energy, residual, multiplier and
// turning-point diagnostics) in the budget's cheap steps (budget.hpp): 141 ns of CPU a step (2.88e7 steps of la-nh
// and contact-nh in 4.05 s: --T 72000 --h 0.005 --alpha 1e-3) against 12 ns for the oscillator's closed-form la
// step in the same build (integrate --system oscillator --h 0.001 --T 20000: 2e7 steps in 0.24 s), 12 cheap steps.
constexpr double foucault_step_cost = 12;
// The memory of one row of the table of an h, held while the runs that made it and the figures that read it back
// live (the runs' samples and turning points, the table read_tsv builds): 572 MB at its peak at --T 2e5 with the
// defaults, whose larger table has 7.0e5 rows (820 bytes a row), rounded up.
constexpr double foucault_row_bytes = 1000;

// Every how many steps a sample is kept: in double first, a sample-dt beyond T (up to 1e308) keeps one sample a
// run (and the turning points), not every step as a long overflowing to its minimum would.
long sample_every(double sample_dt, double h, long N) {
  const double per = std::round(sample_dt / h);
  return per >= static_cast<double>(N) ? std::max(1L, N) : std::max(1L, static_cast<long>(per));
}

std::string trajectory_style(const std::string& scheme) {
  std::string st = plots::style_for(scheme, "lines");
  const auto k = st.find("lw 1.5");
  if (k != std::string::npos) st.replace(k, 6, "lw 0.6");
  return st;
}

}  // namespace

int main(int argc, char** argv) {
  return guarded_main("fig2_foucault", [&] {
    systems::FoucaultPendulum base;  // the scene: the systems' parameters
    std::vector<double> hs{0.1, 0.005}, alphas{1e-3, 1e-4};
    std::vector<std::string> names{"la-nh", "contact-nh"};
    std::string start_name = "legendre", system_name = "foucault";
    double sample_dt = 2;
    Cli cli("fig2_foucault", "Figure 2: damped Foucault pendulum, LA vs contact nonholonomic integrators");
    cli.options.add_options()("h", po::value(&hs)->multitoken()->default_value(hs, "0.1 0.005"),
                              "step sizes (the first is Figure 2, each further one a companion figure)")(
        "alpha", po::value(&alphas)->multitoken()->default_value(alphas, "1e-3 1e-4"), "damping values")(
        "start", po::value(&start_name)->default_value(start_name), "starting procedure: legendre or taylor")(
        "system", po::value(&system_name)->default_value(system_name),
        "the Foucault system: foucault (the paper's discretization of (13), the third row of (15)/(18)) or "
        "foucault-rotation (the remedy); 'paper' and 'rotation' name them too")(
        "schemes", po::value(&names)->multitoken()->default_value(names, "la-nh contact-nh"), "schemes")(
        "sample-dt", po::value(&sample_dt)->default_value(sample_dt),
        "keep a sample every sample-dt seconds (plus every turning point)");
    add_scene_options(cli, base, {"alpha"});
    if (!cli.parse(argc, argv)) return 0;

    // Validate everything before writing anything.
    validate_foucault_sweep(base, hs, alphas);
    base.validate();
    const FoucaultStart start = parse_foucault_start(start_name);
    const std::string system = systems::foucault_system_name(system_name);
    const std::string constraint_name = systems::foucault_discretization(system_name);
    const bool paper = system == systems::Foucault::name;
    const std::string stem0 = paper ? "fig2_foucault" : "fig2_foucault_" + constraint_name;
    for (const auto& n : names)  // a scheme with a closed form on the system (la, contact; la-nh, contact-nh)
      systems::visit_foucault_system(system, [&](auto sys) { generic::visit_closed_form<decltype(sys)>(n, [](auto) {}); });
    require_positive(sample_dt, "sample-dt");
    // The plan, as every program's (budget.hpp): the steps of every h, alpha and scheme against the time budget,
    // and the rows of the largest h's table against the memory available.
    {
      // turning points of a run: two a period of the pendulum (2 pi / sqrt(g/l)), damping aside
      const double turns = base.T * std::sqrt(base.w2()) / geomint::pi + 1;
      const double A = static_cast<double>(alphas.size()), S = static_cast<double>(names.size());
      double steps = 0, rows = 0;
      for (double h : hs) {
        const long N = step_count(h, base.T);
        const double samples = static_cast<double>(N / sample_every(sample_dt, h, N) + 1);
        steps += static_cast<double>(N) * A * S;
        rows = std::max(rows, A * (samples + S * (samples + turns)));
      }
      plan_steps(steps, "the runs (h x alpha x schemes x T/h)", foucault_step_cost);
      check_memory(rows * foucault_row_bytes,
                   "the " + show(rows) + " rows of one h's table (raise --sample-dt or lower --T)");
    }
    const auto dir = prepare_output_dir(cli.out);

    const double s = base.s();
    for (std::size_t ih = 0; ih < hs.size(); ++ih) {
      const double h = hs[ih];
      const long N = step_count(h, base.T);
      const long every = sample_every(sample_dt, h, N);
      const std::string stem = ih == 0 ? stem0 : stem0 + "_h" + format_number(h);
      Params params{{"h", format_number(h)},
                          {"T", format_number(base.T)},
                          {"alpha", format_list(alphas)},
                          {"start", start_name},
                          {"constraint", constraint_name},
                          {"sample_every_steps", std::to_string(every)},
                          {"energy", "chord energy at t_j + h/2: m/2|(q_{j+1}-q_j)/h|^2 + m w2/2|(q_j+q_{j+1})/2|^2"},
                          {"angle", "plane angle atan2(y,x) at turning points (local maxima of |q|), unwrapped mod pi"},
                          {"reference", "closed form: q = R(-s t) rho, rho'' = -(w2-s^2) rho - alpha rho'"}};
      for (auto& kv : base.header_params()) params.push_back(kv);
      TsvWriter tsv(dir / (stem + ".tsv"), "fig2_foucault", params,
                    {"scheme", "alpha", "h", "kind", "j", "t", "x", "y", "t_energy", "energy", "lambda",
                     "residual", "angle", "jump"});
      TsvWriter sum(dir / (stem + "_summary.tsv"), "fig2_foucault", params,
                    {"scheme", "alpha", "h", "steps", "status", "E0", "E_final_over_E0", "t_final",
                     "exp_minus_alpha_t", "E_exact_final_over_E0", "max_residual_scaled", "max_abs_residual",
                     "max_abs_lambda", "min_r", "t_min_r", "min_pass_ratio", "t_min_pass_ratio", "turns", "max_jump_deg", "t_max_jump",
                     "max_energy_loss", "t_max_energy_loss", "rate", "rate_over_minus_s"});
      std::printf("h = %g (%ld steps), start %s, constraint %s, -Omega sin(beta) = %.6e rad/s\n", h, N,
                  start_name.c_str(), constraint_name.c_str(), -s);
      std::printf("%-10s %-7s %9s %9s %9s %9s %9s %18s %18s %18s %9s\n", "scheme", "alpha", "E(T)/E0", "e^-aT",
                  "Eex(T)/E0", "max|Phid|", "min r", "closest pass @t", "max jump deg @t", "max E loss @t",
                  "rate/-s");
      for (double a : alphas) {
        systems::FoucaultPendulum sc = base;
        sc.alpha = a;
        const FoucaultParams<double> p(sc);
        const Vec2<double> q0(sc.x0, sc.y0);
        const Vec2<double> v0c = consistent_velocity(p, q0, Vec2<double>(sc.vx0, sc.vy0));
        const double E0 = foucault_energy(p, q0, v0c);
        // Closed-form reference rows at the sample times (energy at t_j + h/2, like the schemes).
        for (long j = 0; j < N; j += every) {
          const double t = static_cast<double>(j) * h;
          const auto xq = foucault_exact(p, q0, v0c, t);
          const auto xe = foucault_exact(p, q0, v0c, t + h / 2);
          const double E = foucault_energy(p, xe.q, xe.v);
          if (!xq.q.allFinite() || !std::isfinite(E))
            throw NumericalFailure(j, "reference", "the closed-form solution or its energy is not finite at t = " +
                                                       show(t) + " (alpha = " + show(a) + ")");
          tsv.row("reference", a, h, "sample", j, t, xq.q(0), xq.q(1), t + h / 2, E, missing_value, missing_value,
                  missing_value, missing_value);
        }
        const double t_fin = base.T - h / 2;
        const auto xf = foucault_exact(p, q0, v0c, t_fin);
        const double Eex = foucault_energy(p, xf.q, xf.v) / E0;
        for (const auto& n : names) {
          FoucaultRun run;
          std::string status = "ok";
          try {
            run = run_foucault(system, n, sc, h, start, every);
          } catch (const NumericalFailure& e) {
            status = e.what();  // a failed run is data: recorded, the sweep goes on
          }
          std::map<long, const FoucaultTurn*> turn_at;
          for (const auto& k : run.turns) turn_at[k.j] = &k;
          for (const auto& smp : run.samples) {
            const auto it = smp.turning ? turn_at.find(smp.j) : turn_at.end();
            const bool tp = it != turn_at.end();
            tsv.row(n, a, h, tp ? "turn" : "sample", smp.j, smp.t, smp.x, smp.y, smp.t + h / 2, smp.energy,
                    smp.lambda, smp.residual, tp ? it->second->angle : missing_value,
                    tp ? it->second->jump : missing_value);
          }
          const auto& S = run.summary;
          const bool ok = status == "ok";
          const double nan = missing_value;
          sum.row(n, a, h, N, status, ok ? S.E0 : nan, ok ? S.E_final / S.E0 : nan, ok ? S.t_final : nan,
                  std::exp(-a * t_fin), Eex, ok ? S.max_residual : nan, ok ? S.max_abs_residual : nan,
                  ok ? S.max_abs_lambda : nan, ok ? S.min_r : nan, ok ? S.t_min_r : nan, ok && std::isfinite(S.min_pass_ratio) ? S.min_pass_ratio : nan,
                  ok && std::isfinite(S.min_pass_ratio) ? S.t_min_pass_ratio : nan, S.turns,
                  ok ? S.max_jump * deg : nan, ok ? S.t_max_jump : nan, ok ? S.max_energy_loss : nan,
                  ok ? S.t_max_energy_loss : nan, ok ? S.rate : nan, ok ? S.rate / -s : nan);
          if (!ok) {
            std::printf("%-10s %-7g failed: %s\n", n.c_str(), a, status.c_str());
            continue;
          }
          std::printf("%-10s %-7g %9.5f %9.5f %9.5f %9.2e %9.2e %8.2e @%7.1f %8.4f @%7.1f %8.2e @%7.1f %9.5f\n",
                      n.c_str(), a, S.E_final / S.E0, std::exp(-a * t_fin), Eex, S.max_residual, S.min_r,
                      S.min_pass_ratio, S.t_min_pass_ratio, S.max_jump * deg, S.t_max_jump, S.max_energy_loss,
                      S.t_max_energy_loss, S.rate / -s);
        }
      }
      std::printf("\n");
      tsv.commit();
      sum.commit();

      // Figures, from the saved file.
      const auto t = plots::read_tsv(dir / (stem + ".tsv"));
      const std::string where = "h = " + format_number(h) + ", T = " + format_number(base.T) + " s, q_0 = (" +
                                format_number(base.x0) + ", " + format_number(base.y0) + "), start " + start_name +
                                (paper ? "" : ", constraint " + constraint_name);
      plots::Figure fig;
      fig.title = "Foucault pendulum, " + where;
      fig.rows = 2;
      fig.cols = static_cast<int>(alphas.size());
      fig.width_in = 4.6 * fig.cols;
      fig.height_in = 7.5;
      std::vector<std::string> all_names = names;
      all_names.push_back("reference");
      for (int row = 0; row < 2; ++row)
        for (double a : alphas) {
          plots::Panel p;
          if (row == 0)
            p.setup = "set xlabel 't (s)'\nset ylabel 'energy (J)'\nset key top right\nset title 'energy, alpha = " +
                      format_number(a) + "'\n";
          else
            // Axes autoscaled, not equal: the fan spans only ~11 degrees in an hour.
            p.setup = "set xlabel 'x (m)'\nset ylabel 'y (m)'\nset key top right\n"
                      "set title 'bob trajectory, alpha = " + format_number(a) + "'\n";
          for (const auto& n : all_names) {
            if (row == 1 && n == "reference") continue;
            auto keep = [&](size_t i) { return t.text(i, "scheme") == n && t.number(i, "alpha") == a; };
            if (row == 0)
              p.series.push_back({t.numbers("t_energy", keep), t.numbers("energy", keep),
                                  n == "reference" ? "exact (closed form)" : n, plots::style_for(n)});
            else
              p.series.push_back({t.numbers("x", keep), t.numbers("y", keep), n, trajectory_style(n)});
          }
          fig.panels.push_back(std::move(p));
        }
      fig.draw(dir / stem);

      // The plane of oscillation at the turning points against the exact theta0 - s t.
      plots::Figure plane;
      plane.title = "Plane of oscillation minus its exact angle (theta_0 - Omega sin(beta) t), " + where;
      plane.cols = static_cast<int>(alphas.size());
      plane.width_in = 4.6 * plane.cols;
      plane.height_in = 4;
      const double theta0 = std::atan2(base.y0, base.x0);
      for (double a : alphas) {
        plots::Panel p;
        p.setup = "set xlabel 't (s)'\nset ylabel 'plane angle error (deg)'\nset key top left\nset title 'alpha = " +
                  format_number(a) + "'\n";
        for (const auto& n : names) {
          auto keep = [&](size_t i) {
            return t.text(i, "scheme") == n && t.number(i, "alpha") == a && t.text(i, "kind") == "turn";
          };
          const auto tt = t.numbers("t", keep);
          auto ang = t.numbers("angle", keep);
          for (size_t i = 0; i < ang.size(); ++i) {
            // the exact angle, taken modulo pi nearest the measured one
            const double ex = theta0 - s * tt[i];
            ang[i] = nearest_branch(ang[i] - ex, 0.0, geomint::pi) * deg;
          }
          p.series.push_back({tt, ang, n, plots::style_for(n, "linespoints pt 7 ps 0.3")});
        }
        plane.panels.push_back(std::move(p));
      }
      plane.draw(dir / (stem + "_plane"));
    }
    return 0;
  });
}
