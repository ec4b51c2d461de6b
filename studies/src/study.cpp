#include "geomint/study.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>

#include <gsl/gsl_fit.h>

#include "geomint/budget.hpp"
#include "geomint/error.hpp"
#include "geomint/interrupt.hpp"
#include "geomint/io.hpp"
#include "geomint/record.hpp"
#include "geomint/step_cost.hpp"
#include "geomint/sweep.hpp"

namespace geomint {

std::string FitBand::describe() const {
  return "errors in (" + format_number(floor) + ", " + format_number(ceiling) + ")";
}

FitBand fit_band(bool exact_reference, double tol, double size) {
  FitBand b;
  if (!exact_reference) b.floor = reference_floor_factor * tol;
  if (std::isfinite(size) && size > 0) b.ceiling = size;
  return b;
}

double solution_size(const Reference& ref, ErrorNorm norm) {
  double size = 0;
  const std::size_t n = static_cast<std::size_t>(ref.n);
  for (std::size_t j = 0; j * n < ref.q.size(); ++j) {
    double r = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const double x = ref.q[j * n + i];
      r = norm == ErrorNorm::max ? std::max(r, std::abs(x)) : std::hypot(r, x);
    }
    size = std::max(size, r);
  }
  return size;
}

OrderFit fit_order(const std::vector<double>& h, const std::vector<double>& err, double floor) {
  return fit_order(h, err, FitBand{floor});
}

OrderFit fit_order(const std::vector<double>& h, const std::vector<double>& err, const FitBand& band) {
  require(h.size() == err.size(), "fit_order: h and err differ in length");
  std::vector<double> x, y;
  for (size_t i = 0; i < h.size(); ++i) {
    if (band.holds(err[i]) && h[i] > 0) {
      x.push_back(std::log(h[i]));
      y.push_back(std::log(err[i]));
    }
  }
  OrderFit fit;
  fit.points = static_cast<int>(x.size());
  if (x.size() < 3) return fit;
  double c0, c1, cov00, cov01, cov11, sumsq;
  gsl_fit_linear(x.data(), 1, y.data(), 1, x.size(), &c0, &c1, &cov00, &cov01, &cov11, &sumsq);
  fit.slope = c1;
  fit.intercept = c0;
  return fit;
}

std::vector<double> observed_orders(const std::vector<double>& h, const std::vector<double>& err) {
  std::vector<double> out(h.size(), missing_value);
  // an error of 0 (a run exact to the last bit, or a zero solution) has no order: it stays missing
  for (size_t i = 1; i < h.size(); ++i)
    if (err[i - 1] != 0 && err[i] != 0) out[i] = std::log(err[i - 1] / err[i]) / std::log(h[i - 1] / h[i]);
  return out;
}

std::vector<double> halving_sequence(double h0, double h_min) {
  require_positive(h0, "h_max");
  require_positive(h_min, "h_min");
  require(h_min <= h0, "h_min must not exceed h_max");
  std::vector<double> hs{h0};
  while (hs.back() > h_min) hs.push_back(hs.back() / 2);
  return hs;
}

AsymptoticOrder asymptotic_order(const std::vector<double>& h, const std::vector<double>& err, double spread,
                                 double floor) {
  return asymptotic_order(h, err, FitBand{floor}, spread);
}

AsymptoticOrder asymptotic_order(const std::vector<double>& h, const std::vector<double>& err, const FitBand& band,
                                 double spread) {
  require(h.size() == err.size(), "asymptotic_order: h and err differ in length");
  AsymptoticOrder a;
  a.band = band;
  std::vector<double> x, y;  // the usable points, in the given order (coarse to fine)
  for (std::size_t i = 0; i < h.size(); ++i)
    if (band.holds(err[i]) && h[i] > 0) {
      x.push_back(h[i]);
      y.push_back(err[i]);
    } else if (std::isfinite(err[i])) {
      ++a.dropped;
    }
  if (x.size() < 2) return a;
  for (std::size_t k = 1; k < x.size(); ++k) a.local_orders.push_back(std::log(y[k - 1] / y[k]) / std::log(x[k - 1] / x[k]));
  // the finest local orders that agree within `spread`
  const std::size_t L = a.local_orders.size();
  std::size_t first = L - 1;
  double lo = a.local_orders[first], hi = lo;
  while (first > 0) {
    const double p = a.local_orders[first - 1];
    if (std::max(hi, p) - std::min(lo, p) > spread) break;
    lo = std::min(lo, p);
    hi = std::max(hi, p);
    --first;
  }
  // local orders first..L-1 join points first..L
  a.points = static_cast<int>(L - first + 1);
  a.h_max = x[first];
  a.h_min = x[L];
  if (a.points >= 3) {
    a.status = AsymptoticOrder::Status::asymptotic;
    a.slope = fit_order(std::vector<double>(x.begin() + static_cast<long>(first), x.end()),
                        std::vector<double>(y.begin() + static_cast<long>(first), y.end()), band)
                  .slope;
  } else {
    a.status = AsymptoticOrder::Status::pre_asymptotic;
    a.slope = a.local_orders.back();
  }
  return a;
}

std::string AsymptoticOrder::describe() const {
  char b[160];
  // points outside the band are named: a fit that left them out says so
  const std::string outside =
      dropped ? "; " + std::to_string(dropped) + " point" + (dropped > 1 ? "s" : "") + " outside the " + band.describe() : "";
  switch (status) {
    case Status::asymptotic:
      std::snprintf(b, sizeof b, "order %.3f over h = %.4g ... %.4g (%d points)", slope, h_max, h_min, points);
      return b + outside;
    case Status::pre_asymptotic: {
      std::string s = "pre-asymptotic: local orders";
      for (double p : local_orders) {
        std::snprintf(b, sizeof b, " %.3f", p);
        s += b;
      }
      return s + " (no three finest points agree within the spread)" + outside;
    }
    case Status::too_few_points: break;
  }
  return "no order: fewer than two points with " + band.describe() + " (the reference's floor and blow-up)";
}

void fit_series(ConvergenceSeries& s) {
  s.local_order = observed_orders(s.h, s.err);
  s.fit = fit_order(s.h, s.err, s.band);
  s.asymptotic = asymptotic_order(s.h, s.err, s.band);
}

namespace {
struct Point {
  double size = missing_value;  // of the combination's reference solution (the fits' ceiling)
  double err = missing_value;
  std::vector<double> measures;
  std::string failure;
};
}  // namespace

void plan_convergence(const SystemInfo& sys, const std::vector<ParamValues>& combos,
                      const std::vector<std::string>& schemes, const std::vector<double>& hs, Path path) {
  double cost = 0;  // of one step of every scheme, in cheap steps
  for (const auto& s : schemes) cost += step_cost(sys, s, path);
  for (const auto& pv : combos)
    for (double h : hs)
      plan_steps(static_cast<double>(step_count(h, sys.horizon(pv))), "the sweep (combinations x schemes x T/h)",
                 cost);
}

double reference_step(const SystemInfo& sys, const std::vector<double>& hs) {
  require(!hs.empty(), "a study needs h");
  const double finest = *std::min_element(hs.begin(), hs.end());
  return sys.measures.empty() ? finest : finest / 2;
}

ConvergenceStudy convergence_study(const SystemInfo& sys, const std::vector<ParamValues>& combos,
                                   const std::vector<std::string>& schemes, const std::vector<double>& hs, Path path,
                                   ReferenceKind kind, double tol, const Sweep& sweep, ErrorNorm norm) {
  require(!hs.empty() && !schemes.empty() && !combos.empty(), "a convergence study needs h, schemes and parameters");
  check_reference(sys, kind, tol);
  const double h_ref = reference_step(sys, hs);
  const std::size_t M = sys.measures.size();
  for (const auto& pv : combos) check_reference_memory(sys, kind, step_count(h_ref, sys.horizon(pv)));
  // Every (combination, scheme, h) run is an item of the sweep (cost ~ 1/h); a rank computes the reference of a
  // combination when it first needs it.
  const std::size_t S = schemes.size(), H = hs.size(), n_items = combos.size() * S * H;
  std::vector<double> cost(n_items);
  for (std::size_t k = 0; k < n_items; ++k) cost[k] = 1 / hs[k % H];
  std::string ref_kind;
  Task task("convergence", "runs", static_cast<double>(n_items));  // a watched call's progress (interrupt.hpp)
  const auto points = sweep.map<Point>(
      n_items, cost,
      [&](std::size_t first, std::size_t last) {
        std::vector<Point> out;
        std::size_t ref_of = SIZE_MAX;
        Reference ref;
        double ref_size = missing_value;
        std::optional<NumericalFailure> ref_failure;  // a combination whose reference fails (a closed form that overflows) is missing
        for (std::size_t k = first; k < last; ++k) {
          const std::size_t c = k / (S * H);
          const ParamValues& pv = combos[c];
          const std::string& name = schemes[k / H % S];
          if (ref_of != c) {
            ref_of = c;
            ref_failure.reset();
            try {
              ref = sys.reference(pv, h_ref, step_count(h_ref, sys.horizon(pv)), kind, tol);
              ref_kind = ref.kind;
              ref_size = solution_size(ref, norm);
            } catch (const NumericalFailure& f) {
              if (combos.size() == 1) throw;  // a study of one combination has nothing left to show
              ref_failure = f;
            }
          }
          Point p;
          p.size = ref_size;
          p.measures.assign(M, missing_value);
          try {
            if (ref_failure) throw *ref_failure;
            const auto values = sys.measure_run(pv, name, hs[k % H], path, ref, norm);
            p.err = values.front();
            p.measures.assign(values.begin() + 1, values.end());
          } catch (const NumericalFailure& f) {
            p.failure = f.what();
            std::string where = "parameters";  // the failure names the system, scheme and h already
            for (const auto& [k, v] : pv) where += " " + k + "=" + format_number(v);
            report_missing(pv.empty() ? "defaults" : where, p.failure);
          }
          out.push_back(p);
          task.add();
        }
        return out;
      },
      [](const Point& p) { return std::move(RowWriter().put(p.size).put(p.err).put(p.measures).put(p.failure)).str(); },
      [](const std::string& row) {
        Point p;
        RowReader(row).get(p.size).get(p.err).get(p.measures).get(p.failure);
        return p;
      });
  ConvergenceStudy study;
  if (!sweep.root()) return study;
  for (std::size_t c = 0; c < combos.size() && ref_kind.empty(); ++c) {
    try {  // every item ran on other ranks (or every reference failed here): name the reference all the same
      ref_kind = sys.reference(combos[c], hs.front(), 1, kind, tol).kind;
    } catch (const NumericalFailure&) {
    }
  }
  study.reference = ref_kind;
  study.norm = norm;
  study.measures = sys.measures;
  const bool exact = kind == ReferenceKind::exact || (kind == ReferenceKind::automatic && sys.has_exact);
  for (std::size_t c = 0; c < combos.size(); ++c)
    for (std::size_t si = 0; si < S; ++si) {
      ConvergenceSeries s;
      s.scheme = schemes[si];
      s.params = combos[c];
      s.h = hs;
      s.expected_order = sys.scheme(schemes[si]).order;
      for (std::size_t i = 0; i < H; ++i) {
        const Point& p = points[(c * S + si) * H + i];
        s.err.push_back(p.err);
        s.measures.push_back(p.measures);
        s.failure.push_back(p.failure);
        s.steps.push_back(step_count(hs[i], sys.horizon(combos[c])));
      }
      // every point of a combination read the same reference: its first has its size
      s.band = fit_band(exact, tol, points[(c * S + si) * H].size);
      fit_series(s);
      study.series.push_back(std::move(s));
    }
  return study;
}

}  // namespace geomint
