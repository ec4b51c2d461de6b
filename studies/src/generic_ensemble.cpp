#include "geomint/generic_ensemble.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <exception>
#include <stdexcept>
#include <thread>

#include "geomint/budget.hpp"
#include "geomint/error.hpp"
#include "geomint/interrupt.hpp"
#include "geomint/parallel.hpp"
#include "geomint/step_cost.hpp"
#include "geomint/sweep.hpp"

namespace geomint {

namespace {

std::uint64_t splitmix64(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

const ParamInfo* find_param(const SystemInfo& sys, const std::string& name) {
  for (const auto& p : sys.params)
    if (p.name == name) return &p;
  return nullptr;
}

EnsembleRun one_run(const SystemInfo& sys, const EnsembleSpec& spec, long k, long N) {
  EnsembleRun r;
  r.k = k;
  const ParamValues pv = ensemble_params(sys, spec, k);
  for (const auto& p : spec.perturb)
    for (const auto& [n, v] : pv)
      if (n == p.name) r.values.push_back(v);
  try {
    const Run run = sys.run(pv, spec.scheme, spec.h, spec.path, N);  // keeps t = 0 and t = T only
    const std::size_t last = run.t.size() - 1, n = static_cast<std::size_t>(run.n);
    r.q.assign(run.q.begin() + static_cast<long>(last * n), run.q.begin() + static_cast<long>((last + 1) * n));
    r.v.assign(run.v.begin() + static_cast<long>(last * n), run.v.begin() + static_cast<long>((last + 1) * n));
    r.z = run.z[last];
    r.energy0 = run.energy.front();
    r.energy = run.energy[last];
    r.max_phi_d = run.max_phi_d;
    r.newton_mean = run.newton_mean;
  } catch (const NumericalFailure& e) {
    r.failure = e.what();
  } catch (const std::domain_error& e) {  // a solver that left its domain
    r.failure = e.what();
  }
  return r;
}

}  // namespace

Perturbation parse_perturbation(const std::string& text) {
  const auto eq = text.find('=');
  require(eq != std::string::npos && eq > 0 && eq + 1 < text.size(),
          "--perturb takes name=spread (e.g. theta0=1e-3), got '" + text + "'");
  Perturbation p{text.substr(0, eq), 0};
  const std::string value = text.substr(eq + 1);
  std::size_t used = 0;
  try {
    p.spread = std::stod(value, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  require(used == value.size() && used > 0, "--perturb " + p.name + ": '" + value + "' is not a number");
  return p;
}

void validate_ensemble(const SystemInfo& sys, const EnsembleSpec& spec) {
  require(spec.runs >= 1 && spec.runs <= 10000000, "runs must be in [1, 1e7], got " + std::to_string(spec.runs));
  require(!spec.perturb.empty(), "name what to perturb: --perturb <parameter>=<spread> ... (--help --system " +
                                     sys.name + " lists the parameters)");
  for (std::size_t i = 0; i < spec.perturb.size(); ++i) {
    const auto& p = spec.perturb[i];
    if (!find_param(sys, p.name)) {
      std::string known;
      for (const auto& q : sys.params)
        if (q.name != "T") known += (known.empty() ? "" : ", ") + q.name;
      throw InputError("--perturb: " + sys.name + " has no parameter '" + p.name + "' (it has " + known + ")");
    }
    require(p.name != "T", "--perturb: T is the horizon, the same for every run (perturb initial data or constants)");
    for (std::size_t j = 0; j < i; ++j)
      require(spec.perturb[j].name != p.name, "--perturb: " + p.name + " is named twice");
    require(std::isfinite(p.spread) && p.spread >= 0,
            "--perturb " + p.name + ": the spread must be a non-negative finite number, got " + show(p.spread));
  }
  require_positive(spec.h, "h");
  sys.scheme(spec.scheme);
  sys.validate(spec.base);
  step_count(spec.h, sys.horizon(spec.base));
  // every run's own parameters: a perturbation can leave the system's domain (a negative mass, e >= 1)
  for (long k = 0; k < spec.runs; ++k) {
    interruption_point();
    try {
      sys.validate(ensemble_params(sys, spec, k));
    } catch (const InputError& e) {
      throw InputError("run " + std::to_string(k) + " of the ensemble (its perturbed parameters): " + e.what() +
                       " (lower the spreads)");
    }
  }
}

double ensemble_sample(std::uint64_t seed, long k, std::size_t i) {
  // a counter-based stream: the bits of (seed, k, i) alone, 53 of them mapped to [-1, 1)
  const std::uint64_t x =
      splitmix64(splitmix64(splitmix64(seed) ^ static_cast<std::uint64_t>(k)) ^ static_cast<std::uint64_t>(i));
  return static_cast<double>(x >> 11) * 0x1.0p-52 - 1.0;
}

ParamValues ensemble_params(const SystemInfo& sys, const EnsembleSpec& spec, long k) {
  ParamValues pv = spec.base;
  for (std::size_t i = 0; i < spec.perturb.size(); ++i) {
    const auto& p = spec.perturb[i];
    const double u = ensemble_sample(spec.seed, k, i);
    auto it = std::find_if(pv.begin(), pv.end(), [&](const auto& nv) { return nv.first == p.name; });
    if (it != pv.end()) {
      it->second += p.spread * u;
    } else {  // not overridden in the base: the system's default
      const ParamInfo* d = find_param(sys, p.name);
      require(d != nullptr, "--perturb: " + sys.name + " has no parameter '" + p.name + "'");
      pv.emplace_back(p.name, d->value + p.spread * u);
    }
  }
  return pv;
}

std::vector<EnsembleRun> run_ensemble(const SystemInfo& sys, const EnsembleSpec& spec, long first, long last,
                                      unsigned threads, const std::function<void(std::size_t, std::size_t)>& report) {
  const long N = step_count(spec.h, sys.horizon(spec.base));
  const std::size_t n = static_cast<std::size_t>(std::max(0L, last - first));
  std::vector<EnsembleRun> out(n);
  std::atomic<std::size_t> done{0};
  Task task("ensemble", "runs", static_cast<double>(n));  // a watched call's progress (interrupt.hpp)
  // a failure that is not numerical (those are data) stops every thread and is rethrown once (parallel_for)
  auto work = [&] {
    parallel_for(n, threads, [&](std::size_t i) {
      out[i] = one_run(sys, spec, first + static_cast<long>(i), N);
      done.fetch_add(1);
      task.add();
    });
  };
  if (!report) {
    work();
    return out;
  }
  // with a progress callback the runs go on beside the calling thread, which only reports
  std::exception_ptr error;
  std::atomic<bool> finished{false};
  std::thread runner([&] {
    try {
      work();
    } catch (...) {
      error = std::current_exception();
    }
    finished = true;
  });
  while (!finished.load()) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    if (!finished.load()) report(done.load(), n);
  }
  runner.join();
  if (error) std::rethrow_exception(error);
  report(n, n);
  return out;
}

std::string pack(const EnsembleRun& r) {
  RowWriter w;
  w.put(r.k).put(r.values).put(r.failure).put(r.q).put(r.v).put(r.z).put(r.energy0).put(r.energy).put(r.max_phi_d).put(
      r.newton_mean);
  return std::move(w).str();
}

EnsembleRun unpack_ensemble_run(const std::string& row) {
  EnsembleRun r;
  RowReader rd(row);
  rd.get(r.k).get(r.values).get(r.failure).get(r.q).get(r.v).get(r.z).get(r.energy0).get(r.energy).get(r.max_phi_d).get(
      r.newton_mean);
  require(rd.done(), "ensemble: a gathered row is longer than one run");
  return r;
}

void plan_ensemble(const SystemInfo& sys, const EnsembleSpec& spec, const std::string& lower) {
  require(spec.runs >= 1 && spec.runs <= 10000000, "runs must be in [1, 1e7], got " + std::to_string(spec.runs));
  sys.validate(spec.base);
  const long N = step_count(spec.h, sys.horizon(spec.base));
  plan_steps(static_cast<double>(spec.runs) * static_cast<double>(N), "the ensemble (runs x T/h)",
             step_cost(sys, spec.scheme, spec.path));
  check_memory(static_cast<double>(spec.runs) * ensemble_run_bytes(sys.dof, spec.perturb.size()),
               "the ensemble's " + std::to_string(spec.runs) + " runs (lower " + lower + ")");
}

double ensemble_run_bytes(int dof, std::size_t perturbed) {
  // the struct, its vectors' elements, a failure message's worth of text, and its packed copy while gathered
  const double own = static_cast<double>(sizeof(EnsembleRun)) +
                     static_cast<double>(sizeof(double)) * (2.0 * dof + static_cast<double>(perturbed)) + 128;
  return 2 * own;
}

}  // namespace geomint
