// The modified equation of any registered scheme on any registered system, at one point, to order K:
//   q'' = F_0 + h F_1 + ... + h^K F_K   (contact: also z' = Z_0 + h Z_1 + ...; constrained: the modified
//   multiplier mu_k and the modified constraint Phi_h = sum h^k phi_k on which the discrete solution lies),
// computed by pushing truncated power series through the scheme's own residual (geomint/modified/automatic.hpp).
//   modified_equation [--system pendulum] [--scheme la contact] [--order 4] [--t 0] [--q 0.5] [--v 0.3] [--z 0]
//                     [--param alpha=0.1 ...] [--out out]
// Defaults: the damped pendulum at (q, q') = (0.5, 0.3), alpha = 0.1 (its default), K = 4, LA and contact.
// Writes out/modified_equation.tsv (columns system, scheme, alpha, k, component, value; component F<i> is the
// i-th component of F_k, Z the z' coefficient (for contact also the modified Herglotz Lagrangian), L the
// modified (meshed) Lagrangian of an unconstrained LA scheme, mu<c> the multiplier, phi<c> the modified
// constraint, residual
// the self-check: the largest residual coefficient that must vanish) and prints it as a table.
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "geomint/cli.hpp"
#include "geomint/error.hpp"
#include "geomint/io.hpp"
#include "geomint/modified/automatic_registry.hpp"
#include "geomint/registry.hpp"

using namespace geomint;
using namespace geomint::modified;

namespace {

ParamValues parse_params(const std::vector<std::string>& items) {
  ParamValues out;
  for (const auto& s : items) {
    const auto eq = s.find('=');
    require(eq != std::string::npos && eq > 0, "--param expects NAME=VALUE, got '" + s + "'");
    const std::string name = s.substr(0, eq), value = s.substr(eq + 1);
    std::size_t used = 0;
    double x = 0;
    try {
      x = std::stod(value, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    require(used == value.size() && !value.empty() && std::isfinite(x), "--param " + name + ": not a finite number: '" + value + "'");
    out.emplace_back(name, x);
  }
  return out;
}

double param_value(const SystemInfo& info, const ParamValues& pv, const std::string& name) {
  for (const auto& [k, x] : pv)
    if (k == name) return x;
  for (const auto& p : info.params)
    if (p.name == name) return p.value;
  return std::nan("");
}

}  // namespace

int main(int argc, char** argv) {
  return guarded_main("modified_equation", [&] {
    std::string system = "pendulum";
    std::vector<std::string> schemes{"la", "contact"}, params;
    int K = 4;
    double t = 0, z = 0;
    std::vector<double> q{0.5}, v{0.3};
    Cli cli("modified_equation", "the modified equation q'' = sum_k h^k F_k of a scheme at a point, to order K");
    cli.options.add_options()("system", po::value(&system)->default_value(system), "system (registry name)")(
        "scheme", po::value(&schemes)->multitoken()->default_value(schemes, "la contact"), "schemes")(
        "order", po::value(&K)->default_value(K), "order K (0..6)")("t", po::value(&t)->default_value(t), "time")(
        "q", po::value(&q)->multitoken()->default_value(q, "0.5"), "position (n components)")(
        "v", po::value(&v)->multitoken()->default_value(v, "0.3"), "velocity q' (n components)")(
        "z", po::value(&z)->default_value(z), "Herglotz action z (contact schemes)")(
        "param", po::value(&params)->multitoken(), "system parameters NAME=VALUE (defaults: the system's)");
    if (!cli.parse(argc, argv)) return 0;

    const auto& info = find_system(system);
    const auto& ms = find_modified_system(system);
    const ParamValues pv = parse_params(params);
    info.validate(pv);
    require(K >= 0 && K <= registry_max_order, "order must be in [0, " + std::to_string(registry_max_order) + "], got " + std::to_string(K));
    require(std::isfinite(t) && std::isfinite(z), "t and z must be finite");
    for (double x : q) require_finite(x, "q");
    for (double x : v) require_finite(x, "v");
    require(static_cast<int>(q.size()) == info.dof && static_cast<int>(v.size()) == info.dof,
            "system '" + system + "' has " + std::to_string(info.dof) + " degrees of freedom: give that many --q and --v values");
    for (const auto& s : schemes) info.scheme(s);

    // Compute everything before writing anything.
    std::vector<ModifiedPoint> points;
    for (const auto& s : schemes) points.push_back(ms.at(pv, s, K, t, q, v, z, true));

    const auto dir = prepare_output_dir(cli.out);
    Params header = info.header(pv);
    header.insert(header.end(), {{"schemes", join_names(schemes)},
                                 {"order", std::to_string(K)},
                                 {"t", format_number(t)},
                                 {"q", format_list(q)},
                                 {"v", format_list(v)},
                                 {"z", format_number(z)},
                                 {"method", "series in (time, h) pushed through the scheme's residual; one solve per order"}});
    TsvWriter tsv(dir / "modified_equation.tsv", "modified_equation", header,
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
    return 0;
  });
}
