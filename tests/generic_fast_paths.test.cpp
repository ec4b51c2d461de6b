// Every hand-derived step is the fast path of a generic scheme: over a long run the two agree step by step
// to round-off growth. Bound: one unit of eps * max|x| per step (linear growth, the worst case for the
// phase error of a neutrally stable oscillation; both sides round a few times per step, independently).
// The measured differences are far below it (printed with -s), while any error in a formula — an O(h)
// term — would exceed it by orders of magnitude.
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <tuple>

#include "geomint/generic/system_info.hpp"
#include "geomint/systems/foucault.hpp"
#include "geomint/systems/nonholonomic_particle.hpp"
#include "geomint/systems/oscillator.hpp"

using namespace geomint;

namespace {

struct Difference {
  double q = 0, p = 0, z = 0, qmax = 0, pmax = 0;
  long steps = 0;
};

template <class Sys, class G, class C>
Difference compare(const Sys& sys, double h, long N) {
  constexpr int n = Sys::dof, m = Sys::constraints;
  Difference d;
  d.steps = N;
  generic::Stepper<Sys, G> st(sys, h);
  st.start(sys.template initial_position<double>(), sys.template initial_velocity<double>());
  sys.template run_fast<C>(h, N, [&](const generic::StepView<double, n, m>& v) {
    if (v.j > 0) st.step();
    const auto& s = st.state();
    REQUIRE(s.j == v.j);
    d.q = std::max(d.q, (s.q - v.q).template lpNorm<Eigen::Infinity>());
    d.p = std::max(d.p, (s.p - v.p).template lpNorm<Eigen::Infinity>());
    d.z = std::max(d.z, std::abs(s.z - v.z));
    d.qmax = std::max(d.qmax, v.q.template lpNorm<Eigen::Infinity>());
    d.pmax = std::max(d.pmax, v.p.template lpNorm<Eigen::Infinity>());
  });
  return d;
}

template <class Sys>
void check_all_fast_paths(const Sys& sys, double h, long N) {
  const double eps = std::numeric_limits<double>::epsilon();
  std::apply([&](auto... fp) {
    (([&] {
       using FP = decltype(fp);
       const auto d = compare<Sys, typename FP::generic, typename FP::closed>(sys, h, N);
       const double bound_q = double(N) * eps * d.qmax, bound_p = double(N) * eps * d.pmax;
       INFO(Sys::name << ": " << FP::closed::name << " vs generic " << generic::scheme_name<typename FP::generic>()
                      << " over " << N << " steps: |dq| " << d.q << " (bound " << bound_q << "), |dp| " << d.p
                      << " (bound " << bound_p << "), |dz| " << d.z);
       CHECK(d.q <= bound_q);
       CHECK(d.p <= bound_p);
       CHECK(d.z <= bound_p * h * 10);  // z accumulates h L per step: |L| <~ |p|^2 ~ 10 |p| here
       WARN(Sys::name << " " << FP::closed::name << ": |dq| = " << d.q << " = " << d.q / bound_q
                      << " of the bound, |dp| = " << d.p << " = " << d.p / bound_p << " of the bound");
     }()),
     ...);
  }, typename Sys::fast_paths{});
}

}  // namespace

TEST_CASE("oscillator closed forms (la, contact, la-midpoint, leapfrog, contact-sym) follow their generic schemes",
          "[generic][fast]") {
  for (double alpha : {0.01, 0.5}) {
    systems::Oscillator sys;
    sys.alpha = alpha;
    check_all_fast_paths(sys, 0.1, 200000);
  }
}

TEST_CASE("the Foucault steps (15), (18) follow the generic la and contact schemes, both constraints",
          "[generic][fast]") {
  systems::Foucault paper;  // T = 100 s: a few passes near the origin, none closer than the round-off would amplify
  check_all_fast_paths(paper, 0.1, 1000);
  systems::FoucaultRotation rotation;  // the paper's hour
  check_all_fast_paths(rotation, 0.1, 36000);
}

TEST_CASE("the nonholonomic particle's LA step follows the generic la scheme", "[generic][fast]") {
  systems::NonholonomicParticle sys;
  check_all_fast_paths(sys, 0.05, 20000);
}

TEST_CASE("the generic position-momentum form accumulates less round-off than the two-step closed forms",
          "[generic][fast][roundoff]") {
  // Against the same scheme in long double: the closed forms (15), (18) recur in q_{j-1}, q_j, whose difference
  // loses eps |q| / h of velocity every step, and such two-step recurrences accumulate round-off quadratically
  // in the number of steps (Henrici); the generic step carries p_j and stays at linear growth.
  auto measure = [](auto sys, auto g, auto c, double h, long N) {
    using Sys = decltype(sys);
    using G = decltype(g);
    using C = decltype(c);
    generic::Stepper<Sys, G> st(sys, h);
    generic::Stepper<Sys, G, long double> ld(sys, h);
    st.start(sys.template initial_position<double>(), sys.template initial_velocity<double>());
    ld.start(sys.template initial_position<long double>(), sys.template initial_velocity<long double>());
    double gen = 0, fast = 0, qmax = 0;
    sys.template run_fast<C>(h, N, [&](const generic::StepView<double, 2, 1>& v) {
      if (v.j > 0) {
        st.step();
        ld.step();
      }
      const Vec<long double, 2> ref = ld.state().q;
      gen = std::max(gen, double((st.state().q.template cast<long double>() - ref).norm()));
      fast = std::max(fast, double((v.q.template cast<long double>() - ref).norm()));
      qmax = std::max(qmax, v.q.norm());
    });
    const double eps = std::numeric_limits<double>::epsilon(), linear = double(N) * eps * qmax;
    INFO(Sys::name << " " << C::name << ", h = " << h << ", " << N << " steps: generic " << gen << ", closed form " << fast
                   << " off long double (N eps |q| = " << linear << ")");
    CHECK(gen <= linear);
    CHECK(fast <= double(N) * linear);
    CHECK(gen < fast);
    WARN(Sys::name << " " << C::name << ": generic " << gen << ", closed form " << fast << " off long double");
  };
  systems::FoucaultRotation rot;
  rot.scene.alpha = 0.1;
  measure(rot, generic::LaLeft{}, schemes::LaNh{}, 0.025, 160);
  measure(rot, generic::ContactLeft{}, schemes::ContactNh{}, 0.025, 160);
  systems::Foucault paper;
  measure(paper, generic::LaLeft{}, schemes::LaNh{}, 0.1, 1000);
}
