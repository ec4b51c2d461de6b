#pragma once
// The modified equation as formulas within a time budget that holds inside an order. GiNaC has no way to stop a
// call, and one call on a large expression (a normal form of the Chaplygin sleigh's order 4 in q', an exact solve
// with a large right-hand side) runs for seconds, so no check between GiNaC's calls can stop within a second of a
// budget. The formulas are therefore derived in a child
// process, one order after the other (orders 0, 1, ..., K, each a complete result sent back as it is done); at
// the budget (or an interrupt of a watched call, interrupt.hpp) the child is killed and the caller gets the last
// order the child finished, marked stopped. The caller's own process never runs GiNaC, so it is left as it was.
#include <string>

#include "geomint/modified/automatic_registry.hpp"

namespace geomint::modified {

// ms.formulas(pv, scheme, K, budget, on_constraint) with the budget held to about 0.1 s, inside an order. K is the order
// reached (-1 with no rows when not even order 0 was finished); stopped says the budget ran out before order
// K_asked; seconds is the wall time. The child's InputError is rethrown as one. Interrupted (interrupt.hpp) when a
// watched call is stopped meanwhile.
ModifiedFormulas bounded_formulas(const ModifiedSystem& ms, const ParamValues& pv, const std::string& scheme, int K,
                                  double budget_seconds, bool on_constraint = false);

}  // namespace geomint::modified
