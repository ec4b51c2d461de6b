#include "geomint/budget.hpp"

#include <climits>
#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>
#include <utility>

#include "geomint/error.hpp"

namespace geomint {

namespace {
bool g_budget = true;
// per thread: a Python call plans on its own thread, and two threads' calls must not add up (a program plans on
// its main thread alone)
thread_local double g_planned = 0, g_planned_seconds = 0;
std::string g_opt_out = "--no-budget";

std::string count(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}
}  // namespace

void set_budget_enabled(bool enabled) { g_budget = enabled; }
bool budget_enabled() { return g_budget; }
void set_budget_opt_out(const std::string& how) { g_opt_out = how; }

BudgetScope::BudgetScope(bool enabled, std::string opt_out)
    : enabled_(g_budget), steps_(g_planned), seconds_(g_planned_seconds), opt_out_(g_opt_out) {
  g_budget = enabled;
  g_planned = 0;
  g_planned_seconds = 0;
  g_opt_out = std::move(opt_out);
}

BudgetScope::~BudgetScope() {
  g_budget = enabled_;
  g_planned = steps_;
  g_planned_seconds = seconds_;
  g_opt_out = opt_out_;
}

void check_steps(double steps, const std::string& what) {
  require(std::isfinite(steps) && steps < static_cast<double>(LONG_MAX),
          what + ": " + count(steps) + " steps do not fit a long (limit " + count(static_cast<double>(LONG_MAX)) + ")");
  require(steps <= max_steps_per_run,
          what + ": " + count(steps) + " steps exceed the limit of " + count(max_steps_per_run) + " steps per run");
}

void plan_steps(double steps, const std::string& what, double cost) {
  g_planned += steps * cost;
  if (g_budget)
    require(g_planned <= step_budget,
            what + ": " + count(g_planned) + (cost == 1 ? " steps" : " steps (weighted by their cost)") +
                " in all exceed the time budget of " + count(step_budget) + " steps (" + g_opt_out + " to run it anyway)");
}

double available_memory() {
  std::ifstream in("/proc/meminfo");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("MemAvailable:", 0) == 0) {
      std::istringstream ss(line.substr(13));
      double kb = -1;
      ss >> kb;
      return kb >= 0 ? kb * 1024 : -1;
    }
  return -1;
}

void plan_seconds(double seconds, const std::string& what) {
  g_planned_seconds += seconds;
  if (g_budget)
    require(g_planned_seconds <= seconds_budget, what + ": " + count(g_planned_seconds) +
                                                     " s in all exceed the time budget of " + count(seconds_budget) +
                                                     " s (" + g_opt_out + " to run it anyway)");
}

void check_memory(double bytes, const std::string& what) {
  const double avail = available_memory();
  require(std::isfinite(bytes), what + ": the memory needed is not finite");
  if (avail > 0)
    require(bytes <= avail, what + " needs " + count(bytes / 1e6) + " MB, more than the " + count(avail / 1e6) +
                                " MB of memory available");
}

void check_tolerance(double tol, const std::string& name) {
  const double floor = 4 * std::numeric_limits<double>::epsilon();
  require(std::isfinite(tol) && tol > 0, name + " must be a positive finite number, got " + show(tol));
  require(tol >= floor, name + " = " + show(tol) + " is below the precision of a double (limit " + show(floor) + ")");
}

}  // namespace geomint
