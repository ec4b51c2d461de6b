#pragma once
// The schemes a system runs — the generic ones it can, its closed-form fast paths and its extra schemes — by name:
// how the typed code (the registry's translation units, ensembles, benchmarks, tests) finds and visits every method
// that runs on a system. What a run's observer sees is generic/step_view.hpp.
//
// A closed form is a struct, written next to its system (nested in it), with
//   static constexpr const char* name;   a label for tables and messages ("(15), two-step")
//   using solves = generic::LaLeft;       the generic scheme whose equations it solves on this system: the
//                                         registry runs it for that scheme (Path::fast, the default), tests hold
//                                         it to the generic step step by step (tests/generic_checks.hpp)
//   static constexpr const char* alias;   optional: the paper's name for it ("leapfrog", "la-nh"), accepted on
//                                         command lines as the scheme it solves (one entry, one name)
// An extra scheme is a method a system declares beyond the generic ones, with no residual in the generic core
// (a formula as printed, kept to show what it does; a splitting method):
//   static constexpr const char* name, *description;  its scheme name (one registry: it is selectable wherever a
//                                                     scheme is) and one line saying what it is
//   static constexpr int order;           expected order of convergence (0: does not converge)
//   static constexpr bool contact;        its p is a contact momentum and it carries z
//   using solves = void;
// The system lists them and runs any of them from its initial data:
//   using fast_paths = std::tuple<...>;   using extra_schemes = std::tuple<...>;
//   template <class X, class R, class Observer> void run_fast(R h, long N, Observer&& observe) const;
// observe gets the StepView of every q_j, j = 0..N, in the generic schemes' terms (the discrete momentum and
// impulse of the scheme solved), so one observer serves the generic step and every fast path.
// A closed form whose momentum costs more than its positions (a two-step form, whose p_j is the generic scheme's
// Legendre transform computed beside it) may also give the positions alone, for the runs that read only q (an
// error, a timing):
//   template <class X, class R, class Observer> void run_positions(R h, long N, Observer&& observe) const;
// observe(j, t_j, q_j) for j = 0..N, the same q_j as run_fast's.
#include <optional>
#include <string>
#include <tuple>
#include <type_traits>
#include <utility>
#include <vector>

#include "geomint/error.hpp"
#include "geomint/generic/schemes.hpp"
#include "geomint/generic/step_view.hpp"

namespace geomint::generic {

#define GEOMINT_DETECT_TYPE(trait, member)                                              \
  template <class Sys, class = void>                                                    \
  struct trait {                                                                        \
    using type = std::tuple<>;                                                          \
  };                                                                                    \
  template <class Sys>                                                                  \
  struct trait<Sys, std::void_t<typename Sys::member>> {                                \
    using type = typename Sys::member;                                                  \
  };
GEOMINT_DETECT_TYPE(fast_paths_of, fast_paths)
GEOMINT_DETECT_TYPE(extra_schemes_of, extra_schemes)
#undef GEOMINT_DETECT_TYPE

// An observer of positions that does nothing: the argument has_run_positions probes run_positions with.
struct PositionSink {
  template <class V>
  void operator()(long, double, const V&) const {}
};
template <class Sys, class X, class = void>
struct has_run_positions : std::false_type {};
template <class Sys, class X>
struct has_run_positions<Sys, X,
                         std::void_t<decltype(std::declval<const Sys&>().template run_positions<X>(1.0, 1L, PositionSink{}))>>
    : std::true_type {};

template <class X, class = void>
struct has_alias : std::false_type {};
template <class X>
struct has_alias<X, std::void_t<decltype(X::alias)>> : std::true_type {};

// The paper's name of a closed form, or "" (none).
template <class C>
constexpr const char* alias_of() {
  if constexpr (has_alias<C>::value)
    return C::alias;
  else
    return "";
}

// A generic scheme runs on a system when the system has what its principle needs (contact: a Herglotz form).
template <class Sys, class G>
constexpr bool applicable() {
  return !G::contact || has_herglotz_v<Sys>;
}

// The closed form of generic scheme G on Sys, or void.
template <class Sys, class G, class Paths = typename fast_paths_of<Sys>::type>
struct closed_form_for;
template <class Sys, class G>
struct closed_form_for<Sys, G, std::tuple<>> {
  using type = void;
};
template <class Sys, class G, class C, class... Cs>
struct closed_form_for<Sys, G, std::tuple<C, Cs...>> {
  using type = std::conditional_t<std::is_same_v<typename C::solves, G>, C,
                                  typename closed_form_for<Sys, G, std::tuple<Cs...>>::type>;
};
template <class Sys, class G>
using closed_form_for_t = typename closed_form_for<Sys, G>::type;

// A generic scheme is a principle over a quadrature; anything else a system runs as a scheme is its own.
template <class X, class = void>
struct is_generic_scheme : std::false_type {};
template <class X>
struct is_generic_scheme<X, std::void_t<typename X::quadrature>> : std::true_type {};
template <class X>
inline constexpr bool is_extra_scheme_v = !is_generic_scheme<X>::value;

// The scheme's one name: a generic scheme's quadrature names it, an extra scheme names itself.
template <class X>
constexpr const char* scheme_name_of() {
  if constexpr (is_extra_scheme_v<X>)
    return X::name;
  else
    return scheme_name<X>();
}

// Every scheme of Sys (its applicable generic schemes, then its extra schemes) by its one name, with the
// aliases of its closed forms; f(X{}) is called for each, in the registry's order.
template <class Sys, class F>
void for_each_scheme(F&& f) {
  std::apply([&](auto... g) {
    (([&] {
       if constexpr (applicable<Sys, decltype(g)>()) f(g);
     }()),
     ...);
  }, AllSchemesTuple{});
  std::apply([&](auto... e) { (f(e), ...); }, typename extra_schemes_of<Sys>::type{});
}

// Whether `name` names scheme X on Sys: its one name, or the paper's name of its closed form there.
template <class Sys, class X>
bool names_scheme(const std::string& name) {
  if (name == scheme_name_of<X>()) return true;
  if constexpr (!is_extra_scheme_v<X>) {
    using C = closed_form_for_t<Sys, X>;
    if constexpr (!std::is_void_v<C>) return name == alias_of<C>() && !std::string(alias_of<C>()).empty();
  }
  return false;
}

template <class Sys>
std::string known_schemes() {
  std::string known;
  for_each_scheme<Sys>([&](auto x) { known += (known.empty() ? "" : ", ") + std::string(scheme_name_of<decltype(x)>()); });
  return known;
}

// Calls f(X{}) for the scheme of Sys named `name` (or an alias); InputError naming the known ones otherwise.
template <class Sys, class F>
decltype(auto) visit_scheme(const std::string& name, F&& f) {
  using First = std::tuple_element_t<0, AllSchemesTuple>;
  using R = decltype(f(First{}));
  if constexpr (std::is_void_v<R>) {
    bool found = false;
    for_each_scheme<Sys>([&](auto x) {
      if (!found && names_scheme<Sys, decltype(x)>(name)) {
        found = true;
        f(x);
      }
    });
    if (!found)
      throw InputError("unknown scheme '" + name + "'" + of_system<Sys>("for") + " (known: " + known_schemes<Sys>() + ")");
  } else {
    std::optional<R> out;
    for_each_scheme<Sys>([&](auto x) {
      if (!out && names_scheme<Sys, decltype(x)>(name)) out.emplace(f(x));
    });
    if (!out)
      throw InputError("unknown scheme '" + name + "'" + of_system<Sys>("for") + " (known: " + known_schemes<Sys>() + ")");
    return R(std::move(*out));
  }
}

// Calls f(G{}) for the generic scheme of Sys named `name` (or an alias): for code that needs a residual (the
// modified equations). InputError for a scheme the system declares as a closed form only, or an unknown name.
template <class Sys, class F>
decltype(auto) visit_generic_scheme(const std::string& name, F&& f) {
  return visit_scheme<Sys>(name, [&](auto x) -> decltype(f(LaLeft{})) {
    using X = decltype(x);
    if constexpr (is_extra_scheme_v<X>) {
      throw InputError(std::string("scheme '") + X::name + "'" + of_system<Sys>() +
                       " is a closed form without a residual: it has no modified equation here");
    } else {
      return f(x);
    }
  });
}

template <class Sys>
std::vector<std::string> generic_scheme_names() {
  std::vector<std::string> names;
  for_each_scheme<Sys>([&](auto x) {
    if constexpr (!is_extra_scheme_v<decltype(x)>) names.push_back(scheme_name_of<decltype(x)>());
  });
  return names;
}

// The closed form that runs scheme X on Sys (X itself for an extra scheme), or void.
template <class Sys, class X>
using runner_of_t = std::conditional_t<is_extra_scheme_v<X>, X, closed_form_for_t<Sys, X>>;

// Calls f(C{}) with the closed form that runs the scheme named `name` on Sys (a fast path, or an extra scheme
// itself): what typed code that steps closed forms directly uses (ensembles, benchmarks). InputError when the
// scheme is unknown or has only the generic step on this system.
template <class Sys, class F>
void visit_closed_form(const std::string& name, F&& f) {
  visit_scheme<Sys>(name, [&](auto x) {
    using C = runner_of_t<Sys, decltype(x)>;
    if constexpr (std::is_void_v<C>)
      throw InputError("scheme '" + std::string(scheme_name_of<decltype(x)>()) + "'" + of_system<Sys>() +
                       " has no closed form");
    else
      f(C{});
  });
}

}  // namespace geomint::generic
