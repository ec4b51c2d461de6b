#pragma once
// EntrySlots<Record>: the plain function pointers of a registry record (SystemInfo, ModifiedSystem) for a model
// known only at run time. A record's operations take no context, so each of a fixed number of slots has its own
// trampolines: slot k's operation installs slot k's model as the call's model (FormulaCall) and runs the shape's
// operation, compiled once for every model of that shape. An entry holds a slot while it lives.
#include <array>
#include <cstddef>
#include <memory>
#include <mutex>
#include <tuple>
#include <type_traits>
#include <utility>

#include "geomint/error.hpp"
#include "geomint/formula/formula_registry.hpp"
#include "geomint/formula/formula_call.hpp"
#include "geomint/formula/time_transform.hpp"

namespace geomint::formula {

template <class Record>
class EntrySlots {
 public:
  static constexpr std::size_t size = max_formula_entries;

  // Takes a free slot for (model, shape) and returns the entry: `record` with its operations (the members listed in
  // Members) pointing at the slot's trampolines. The slot is freed with the last copy of the returned pointer.
  template <auto... Members>
  static std::shared_ptr<const Record> acquire(std::shared_ptr<const FormulaModel> model, const Record* shape, Record record) {
    std::size_t k = size;
    {
      std::lock_guard<std::mutex> lock(mutex());
      for (std::size_t i = 0; i < size && k == size; ++i)
        if (!slots()[i].model) k = i;
      if (k == size)
        throw InputError("system '" + model->name + "': " + std::to_string(size) +
                         " systems defined by formulas are alive at once, the most a process holds (drop some)");
      slots()[k] = {model, shape};
    }
    fill<Members...>(record, k, std::make_index_sequence<size>{});
    return std::shared_ptr<const Record>(new Record(std::move(record)), [k](const Record* r) {
      delete r;
      std::lock_guard<std::mutex> lock(mutex());
      slots()[k] = {};
    });
  }

 private:
  struct Slot {
    std::shared_ptr<const FormulaModel> model;
    const Record* shape = nullptr;
  };
  static std::array<Slot, size>& slots() {
    static std::array<Slot, size> s;
    return s;
  }
  static std::mutex& mutex() {
    static std::mutex m;
    return m;
  }

  template <std::size_t K, auto Member, class Fp>
  struct Trampoline;
  template <std::size_t K, auto Member, class R, class... A>
  struct Trampoline<K, Member, R (*)(A...)> {
    static R call(A... a) {
      const Slot& s = slots()[K];  // a live entry's slot: not written while the entry lives
      const FormulaCall call(s.model);
      if constexpr (std::is_same_v<R, Run>) {
        // A time-transformed model's velocities (and energies) from its momenta, by Newton from the previous row's
        // (time_transform.hpp): the core's inversion starts at Q' = p and can land on another root.
        R run = (s.shape->*Member)(std::forward<A>(a)...);
        if (s.model->time_transformed) time_transform_velocities(*s.model, parameter_table(*s.model, std::get<0>(std::tie(a...))), run);
        return run;
      } else {
        return (s.shape->*Member)(std::forward<A>(a)...);
      }
    }
  };
  template <std::size_t K, auto Member, class Fp, class Owner>
  static void point(Record& r, Fp Owner::*) {
    r.*Member = &Trampoline<K, Member, Fp>::call;
  }
  template <std::size_t K, auto... Members>
  static void fill_slot(Record& r) {
    (point<K, Members>(r, Members), ...);
  }
  template <auto... Members, std::size_t... K>
  static void fill(Record& r, std::size_t k, std::index_sequence<K...>) {
    ((k == K ? fill_slot<K, Members...>(r) : void()), ...);
  }
};

}  // namespace geomint::formula
