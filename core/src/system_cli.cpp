#include "geomint/system_cli.hpp"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>
#include <utility>

#include "geomint/error.hpp"
#include "geomint/formula/formula_registry.hpp"
#include "geomint/generic/composition_families.hpp"
#include "geomint/io.hpp"
#include "geomint/text.hpp"

namespace geomint {

namespace {
// The compositions a system runs when named: families (order, stages) and bases, not every pairing.
std::string composition_caption(const SystemInfo& sys) {
  if (sys.compositions.empty()) return "";
  std::string families;
  for (const auto& f : generic::composition_families())
    families += "\n    " + f.name + ": order " + std::to_string(f.order) + ", " + std::to_string(f.stages()) + " stages";
  return "\n  <family>:<base> (run when named, e.g. " + sys.compositions.front().name +
         "): a composition of a symmetric scheme, base one of " + join_names(sys.composition_bases(), ", ") + "; families:" + families;
}
}  // namespace

// --system X or --system=X in argv (a repeat is refused by Cli::parse later).
std::string find_system_arg(int argc, char** argv, const std::string& fallback) {
  std::string name = fallback;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--system") == 0 && i + 1 < argc) name = argv[i + 1];
    if (std::strncmp(argv[i], "--system=", 9) == 0) name = argv[i] + 9;
  }
  return name;
}

namespace {
// The value of `option` in argv, given as "option VALUE" or "option=VALUE" (the last one wins), and whether it was
// given at all.
std::pair<std::string, bool> find_option_value(int argc, char** argv, const std::string& option) {
  std::string value;
  bool given = false;
  const std::string with_equals = option + "=";
  for (int i = 1; i < argc; ++i) {
    if (argv[i] == option && i + 1 < argc) {
      value = argv[i + 1];
      given = true;
    }
    if (std::strncmp(argv[i], with_equals.c_str(), with_equals.size()) == 0) {
      value = argv[i] + with_equals.size();
      given = true;
    }
  }
  return {value, given};
}
}  // namespace

// --system-file PATH or --system-file=PATH in argv ("" when absent). An empty PATH is refused: it is what an unset
// shell variable gives ("--system-file $F"), and taken as "absent" it ran the default system in its place.
std::string find_system_file_arg(int argc, char** argv) {
  const auto [path, given] = find_option_value(argc, argv, "--system-file");
  require(!given || !path.empty(), "--system-file is given an empty path (an unset shell variable?): name a system file, "
                                   "or leave the option out for the default system");
  return path;
}

// --time-transform G or --time-transform=G in argv ("" when absent; an empty G is refused like an empty path).
std::string find_time_transform_arg(int argc, char** argv) {
  const auto [g, given] = find_option_value(argc, argv, "--time-transform");
  require(!given || !g.empty(), "--time-transform is given an empty formula: give the monitor g (dt = g dsigma), e.g. 1/(1 + v1^2)");
  return g;
}

namespace {
bool has_system_arg(int argc, char** argv) {
  for (int i = 1; i < argc; ++i)
    if (std::strcmp(argv[i], "--system") == 0 || std::strncmp(argv[i], "--system=", 9) == 0) return true;
  return false;
}

// The systems read from files by this process, alive as long as it (a program reads at most one), with their paths
// for the output headers.
struct LoadedSystem {
  std::shared_ptr<const formula::FormulaModel> model;
  std::shared_ptr<const SystemInfo> info;
  std::string path;
  std::string time_transform;  // the monitor g (the command line's, or the file's), "" for none
};
std::vector<LoadedSystem>& loaded_systems() {
  static std::vector<LoadedSystem> loaded;
  return loaded;
}

// A monitor from the command line takes the place of the file's time_transform.
const SystemInfo& system_from_file(const std::string& path, const std::string& time_transform) {
  formula::SystemDescription d = formula::read_system_file(path);
  if (!time_transform.empty()) d.time_transform = formula::formula_text(time_transform, "--time-transform");
  auto model = formula::compile_model(d);
  auto info = formula::formula_system_info(model);
  loaded_systems().push_back({model, info, path, d.time_transform.text});
  return *info;
}
}  // namespace

SystemOptions::SystemOptions(Cli& cli, int argc, char** argv, const std::string& default_system, bool sweep)
    : sweep_(sweep) {
  const std::string file = find_system_file_arg(argc, argv);
  time_transform_ = find_time_transform_arg(argc, argv);
  if (!file.empty()) {
    require(!has_system_arg(argc, argv), "give --system or --system-file, not both");
    system_ = &system_from_file(file, time_transform_);
    file_ = file;
  } else {
    // The transformation is built from a system's formulas: a header system has a formula twin in docs/systems.
    require(time_transform_.empty(), "--time-transform needs a system given by its formulas: --system-file (the header "
                                     "systems are written as formulas in docs/systems/*.geomint, e.g. pendulum.geomint)");
    system_ = &find_system(find_system_arg(argc, argv, default_system));
  }
  given_.resize(system_->params.size());
  std::string known;
  for (const auto& s : system_names()) known += (known.empty() ? "" : " ") + s;
  cli.options.add_options()("system", po::value<std::string>()->default_value(default_system),
                            ("the system (" + known + ")").c_str())(
      "system-file", po::value<std::string>(),
      "a system defined by its formulas (a .geomint file, docs/systems/README.md) instead of --system")(
      "time-transform", po::value<std::string>(),
      "with --system-file: step in a fictitious time sigma, dt = g dsigma, g a formula in t, q1.., v1.. and the "
      "parameters (e.g. 1/(1 + v1^2)); the system gets the time t as its last coordinate (docs/time-transformation.md)");
  // --help --system X: the system's schemes (what --scheme/--schemes take), then its parameters as options
  std::string caption = "Schemes of system '" + system_->name + "':";
  for (const auto& s : system_->schemes) caption += "\n  " + s.name + ": " + s.description();
  caption += composition_caption(*system_);
  caption += "\n\nParameters of system '" + system_->name + "' (" + system_->description + (sweep ? "; several values sweep" : "") + ")";
  po::options_description sys_opts(caption);
  for (std::size_t i = 0; i < system_->params.size(); ++i) {
    const auto& p = system_->params[i];
    // multitoken even when not sweeping, so a second value is an error here rather than a stray word
    auto* v = po::value(&given_[i])->multitoken();
    sys_opts.add_options()(p.name.c_str(), v, (p.doc + " (default " + format_number(p.value) + ")").c_str());
  }
  cli.options.add(sys_opts);
}

std::vector<std::string> SystemOptions::swept() const {
  std::vector<std::string> out;
  for (std::size_t i = 0; i < given_.size(); ++i)
    if (given_[i].size() > 1) out.push_back(system_->params[i].name);
  return out;
}

std::vector<ParamValues> SystemOptions::combinations() const {
  std::vector<ParamValues> combos{{}};
  for (std::size_t i = 0; i < given_.size(); ++i) {
    const auto& vals = given_[i];
    if (vals.empty()) continue;
    require(sweep_ || vals.size() == 1, "--" + system_->params[i].name + " takes one value");
    std::vector<ParamValues> next;
    for (const auto& c : combos)
      for (double v : vals) {
        ParamValues pv = c;
        pv.emplace_back(system_->params[i].name, v);
        next.push_back(std::move(pv));
      }
    combos = std::move(next);
  }
  require(combos.size() <= 10000, "the sweep has " + std::to_string(combos.size()) + " combinations (limit 10000)");
  for (const auto& c : combos) system_->validate(c);
  return combos;
}

ParamValues SystemOptions::values() const {
  const auto c = combinations();
  require(c.size() == 1, "give one value per parameter");
  return c.front();
}

std::vector<std::pair<std::string, std::string>> SystemOptions::header() const {
  std::vector<std::pair<std::string, std::string>> out{{"system", system_->name}};
  for (const auto& l : loaded_systems())
    if (l.info.get() == system_) {
      out.emplace_back("system_file", l.path);
      if (!l.time_transform.empty())
        out.emplace_back("time_transform", "dt = g dsigma, g = " + l.time_transform + " (the time t is the last coordinate)");
    }
  // the start of a system that does not start at t = 0 (a header system always does); t0 may be a formula of the
  // parameters, so it is taken at the values the runs use: one value per combination where a sweep changes it
  if (system_->initial_time) {
    std::vector<double> t0s;
    for (const auto& c : combinations()) t0s.push_back(system_->initial_time(c));
    const bool same = std::all_of(t0s.begin(), t0s.end(), [&](double t) { return t == t0s.front(); });
    if (!same)
      out.emplace_back("t0", format_list(t0s) + " (one per combination of the parameters, in the runs' order; t_j = t0 + j h)");
    else if (!t0s.empty() && t0s.front() != 0)
      out.emplace_back("t0", format_number(t0s.front()) + " (the runs' t_j = t0 + j h)");
  }
  for (std::size_t i = 0; i < given_.size(); ++i)
    out.emplace_back(system_->params[i].name,
                     given_[i].empty() ? format_number(system_->params[i].value) : format_list(given_[i]));
  return out;
}

std::vector<std::string> SystemOptions::schemes(const std::vector<std::string>& asked) const {
  if (asked.empty()) return system_->scheme_names();
  for (const auto& s : asked) system_->scheme(s);  // InputError naming the known ones
  return asked;
}

void SystemOptions::warn_contact(const std::vector<ParamValues>& values, const std::vector<std::string>& schemes) const {
  for (const auto& l : loaded_systems())
    if (l.info.get() == system_)
      for (const auto& why : formula::contact_warnings(l.model, *system_, values, schemes))
        std::fprintf(stderr, "warning: %s\n", one_line(why).c_str());
}

namespace {
// The tokens after --systems in argv (or after --systems=), up to the next option; `fallback` when absent.
std::vector<std::string> find_systems_arg(int argc, char** argv, const std::vector<std::string>& fallback) {
  std::vector<std::string> names = fallback;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--systems") == 0) {
      names.clear();
      for (int k = i + 1; k < argc && std::strncmp(argv[k], "--", 2) != 0; ++k) names.push_back(argv[k]);
    } else if (std::strncmp(argv[i], "--systems=", 10) == 0) {
      names = {argv[i] + 10};
    }
  }
  return names;
}
}  // namespace

SystemsOptions::SystemsOptions(Cli& cli, int argc, char** argv, std::vector<std::string> default_systems,
                               ParamValues presets, const std::string& systems_doc)
    : presets_(std::move(presets)) {
  // The options are those of the systems on this command line; an unknown name is refused here, before the parse
  // would call its parameters unrecognised.
  const auto named = find_systems_arg(argc, argv, default_systems);
  std::vector<std::string> docs, owners;
  for (const auto& name : named) {
    const SystemInfo& sys = find_system(name);
    for (const auto& p : sys.params) {
      const auto it = std::find(params_.begin(), params_.end(), p.name);
      if (it == params_.end()) {
        params_.push_back(p.name);
        docs.push_back(p.doc);
        owners.push_back(name);
      } else {
        owners[static_cast<std::size_t>(it - params_.begin())] += ", " + name;
      }
    }
  }
  given_.resize(params_.size());
  cli.options.add_options()("systems", po::value(&names_)->multitoken()->default_value(default_systems, join_names(default_systems, " ")),
                            (systems_doc + " (" + join_names(system_names(), " ") + ")").c_str());
  po::options_description sys_opts("Parameters of the systems (a value given goes to every system named that has the "
                                   "parameter; otherwise each keeps its default, or the program's preset shown)");
  for (std::size_t i = 0; i < params_.size(); ++i) {
    std::string doc = docs[i] + " (" + owners[i];
    for (const auto& [k, v] : presets_)
      if (k == params_[i]) doc += "; preset " + format_number(v);
    sys_opts.add_options()(params_[i].c_str(), po::value(&given_[i])->multitoken(), (doc + ")").c_str());
  }
  cli.options.add(sys_opts);
}

ParamValues SystemsOptions::values(const std::string& system) const {
  const SystemInfo& sys = find_system(system);
  ParamValues pv;
  for (const auto& p : sys.params) {
    const auto i = static_cast<std::size_t>(std::find(params_.begin(), params_.end(), p.name) - params_.begin());
    if (i < params_.size() && !given_[i].empty()) {
      require(given_[i].size() == 1, "--" + p.name + " takes one value");
      pv.emplace_back(p.name, given_[i].front());
      continue;
    }
    for (const auto& [k, v] : presets_)
      if (k == p.name) pv.emplace_back(k, v);
  }
  sys.validate(pv);
  return pv;
}

std::vector<ParamValues> SystemsOptions::combinations(const std::string& system) const {
  const SystemInfo& sys = find_system(system);
  std::vector<ParamValues> combos{{}};
  for (const auto& p : sys.params) {
    const auto i = static_cast<std::size_t>(std::find(params_.begin(), params_.end(), p.name) - params_.begin());
    std::vector<double> vals;
    if (i < params_.size() && !given_[i].empty()) {
      vals = given_[i];
    } else {
      for (const auto& [k, v] : presets_)
        if (k == p.name) vals = {v};
    }
    if (vals.empty()) continue;
    std::vector<ParamValues> next;
    for (const auto& c : combos)
      for (double v : vals) {
        ParamValues pv = c;
        pv.emplace_back(p.name, v);
        next.push_back(std::move(pv));
      }
    combos = std::move(next);
  }
  require(combos.size() <= 10000, "the sweep has " + std::to_string(combos.size()) + " combinations (limit 10000)");
  for (const auto& c : combos) sys.validate(c);
  return combos;
}

std::vector<std::string> SystemsOptions::swept() const {
  std::vector<std::string> out;
  for (std::size_t i = 0; i < params_.size(); ++i)
    if (given_[i].size() > 1) out.push_back(params_[i]);
  return out;
}

double SystemsOptions::value(const std::string& system, const std::string& param) const {
  return param_value(values(system), find_system(system), param);
}

std::vector<std::pair<std::string, std::string>> SystemsOptions::header() const {
  std::vector<std::pair<std::string, std::string>> out{{"systems", join_names(names_)}};
  for (std::size_t i = 0; i < params_.size(); ++i) {
    if (!given_[i].empty()) {
      out.emplace_back(params_[i], format_list(given_[i]));
      continue;
    }
    for (const auto& [k, v] : presets_)
      if (k == params_[i]) out.emplace_back(k, format_number(v) + " (preset)");
  }
  return out;
}

void add_baseline_study_options(Cli& cli, std::string& equations, std::string& path, std::string& norm, int& reps) {
  cli.options.add_options()(
      "equations", po::value(&equations)->default_value(equations),
      "what the baselines integrate: ad (the acceleration derived from L, F, Phi) or rhs (the system's own)")(
      "path", po::value(&path)->default_value(path), "fast (closed forms where they exist) or generic")(
      "norm", po::value(&norm)->default_value(norm), "max (the largest component of q - q_ref) or 2 (its Euclidean length)")(
      "reps", po::value(&reps)->default_value(reps), "timed repetitions");
}

double param_value(const ParamValues& pv, const SystemInfo& sys, const std::string& name) {
  for (const auto& [k, v] : pv)
    if (k == name) return v;
  for (const auto& p : sys.params)
    if (p.name == name) return p.value;
  throw InputError("no parameter '" + name + "'");
}

}  // namespace geomint
