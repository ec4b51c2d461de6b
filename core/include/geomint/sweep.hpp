#pragma once
// Sweeps beyond one machine: independent runs split across MPI ranks and gathered on rank 0, with output
// byte-identical to a single process. One helper for every sweep program.
//
// How a program adopts it (anomaly_foucault and stability do exactly this):
//
//   ... parse and validate the options (every rank does, identically) ...
//   const auto dir = prepare_output_dir(cli.out, OtherRanks::compute);  // every rank goes on (io.hpp)
//   const auto& sweep = Sweep::world();              // rank/size; no MPI unless started by mpirun
//   std::vector<Result> results = sweep.map<Result>(
//       n_items, cost,                                // cost[i]: relative cost of item i (empty: equal)
//       [&](std::size_t first, std::size_t last) {    // this rank's items, in order
//         return compute(first, last); },             // -> std::vector<Result>, last - first of them
//       pack, unpack);                                // Result <-> std::string (RowWriter / RowReader)
//   if (!sweep.root()) return 0;                      // only rank 0 holds the results and writes files
//   ... write outputs from `results` exactly as before ...
//
// A program that does not call map() keeps prepare_output_dir's default, OtherRanks::leave: its other ranks end
// there at once (exit 0, without starting MPI) and rank 0 runs it alone. Only rank 0 writes, in either case: the
// writers refuse on any other rank (output_run.hpp), and rank 0 alone reports input errors, so a bad option under
// mpiexec is one line in all.
// - In a single process (a build without MPI, or a program not started by an MPI launcher) map() is
//   compute(0, n): no copy, no serialization, nothing else changes.
// - Under `mpirun -n N` each rank computes one contiguous share of [0, n) (share(): equal cost per rank, a
//   deterministic function of n and cost, so every rank agrees without talking), packs its results, and
//   rank 0 gathers them in item order. Results must therefore not depend on which rank computed them (no
//   per-rank seeds, no timing inside a result); threads inside a rank are the program's own business.
// - Items are packed to bytes with RowWriter/RowReader (trivially copyable values, strings, vectors of
//   trivially copyable values). Ranks run the same binary on the same architecture, so doubles travel as
//   their bytes: bit-exact, no decimal round trip.
// - MPI is detected at run time from the launcher's environment (Open MPI, MPICH/Hydra, PMIx, Slurm's PMI)
//   and initialized on first use of world(), finalized at exit. Every rank must reach map(): validate input
//   identically on every rank before it. A rank that fails alone once MPI has started ends them all
//   (guarded_main calls abort_all): the others would otherwise wait for it forever.
#include <cstddef>
#include <cstring>
#include <functional>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace geomint {

// Bytes of one result row. put/get in the same order.
class RowWriter {
 public:
  template <class T>
  RowWriter& put(const T& v) {
    static_assert(std::is_trivially_copyable_v<T>, "RowWriter::put: trivially copyable values only");
    buf_.append(reinterpret_cast<const char*>(&v), sizeof v);
    return *this;
  }
  RowWriter& put(const std::string& s) {
    put(static_cast<std::size_t>(s.size()));
    buf_.append(s);
    return *this;
  }
  template <class T>
  RowWriter& put(const std::vector<T>& v) {
    static_assert(std::is_trivially_copyable_v<T>, "RowWriter::put: vectors of trivially copyable values only");
    put(static_cast<std::size_t>(v.size()));
    buf_.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
    return *this;
  }
  std::string str() && { return std::move(buf_); }
  const std::string& str() const& { return buf_; }

 private:
  std::string buf_;
};

class RowReader {
 public:
  explicit RowReader(const std::string& row) : row_(row) {}
  template <class T>
  RowReader& get(T& v) {
    static_assert(std::is_trivially_copyable_v<T>, "RowReader::get: trivially copyable values only");
    take(&v, sizeof v);
    return *this;
  }
  RowReader& get(std::string& s) {
    std::size_t n = 0;
    get(n);
    check(n);
    s.assign(row_, pos_, n);
    pos_ += n;
    return *this;
  }
  template <class T>
  RowReader& get(std::vector<T>& v) {
    std::size_t n = 0;
    get(n);
    check(n * sizeof(T));
    v.resize(n);
    take(v.data(), n * sizeof(T));
    return *this;
  }
  bool done() const { return pos_ == row_.size(); }

 private:
  void check(std::size_t bytes) const;  // throws if the row is shorter
  void take(void* dst, std::size_t bytes) {
    check(bytes);
    if (bytes) std::memcpy(dst, row_.data() + pos_, bytes);
    pos_ += bytes;
  }
  const std::string& row_;
  std::size_t pos_ = 0;
};

class Sweep {
 public:
  // The process's place in the sweep: (rank, size) of MPI_COMM_WORLD under an MPI launcher, (0, 1) otherwise.
  static const Sweep& world();

  int rank() const { return rank_; }
  int size() const { return size_; }
  bool root() const { return rank_ == 0; }
  bool distributed() const { return size_ > 1; }
  static bool mpi_available();  // was the build made with MPI

  // This process's rank as its MPI launcher announced it in the environment (OMPI_COMM_WORLD_RANK, PMIX_RANK,
  // PMI_RANK), known before MPI starts and without starting it: 0 in a process no MPI launcher started. Rank 0
  // speaks for a run (its errors, its interrupt line, --help) and alone writes its outputs. A launcher that
  // names no rank: MPI is started to ask.
  static int launcher_rank();
  // Rank 0's text on every rank, a collective (every rank calls it); a single process gets its own back. How
  // the ranks agree on an outcome only rank 0 can know (its output folder could be prepared).
  std::string broadcast(const std::string& from_root) const;
  // A rank that fails alone ends them all (MPI_Abort with `status`, the launcher's exit status then) when MPI
  // was started and more than one rank runs; otherwise returns. Without it the others would wait forever in
  // the next collective, and the failed rank with them in MPI_Finalize.
  static void abort_all(int status);
  // Has MPI been started (and not yet finalized) with more than one rank?
  static bool started();

  // This rank's share [first, last) of items [0, n): contiguous, in rank order, with about equal total cost
  // (cost[i] >= 0; empty: every item costs 1).
  std::pair<std::size_t, std::size_t> share(std::size_t n, const std::vector<double>& cost = {}) const {
    return share_of(rank_, size_, n, cost);
  }
  // The same for any (rank, size): what share() computes, testable in one process.
  static std::pair<std::size_t, std::size_t> share_of(int rank, int size, std::size_t n,
                                                      const std::vector<double>& cost = {});

  // Gathers every rank's rows on rank 0, rank after rank (so in item order when each rank sends its share
  // in order); other ranks get an empty vector. A single process gets `mine` back.
  std::vector<std::string> gather(std::vector<std::string> mine) const;

  // The whole pattern: compute(first, last) on this rank's share, gathered on rank 0 in item order.
  template <class Result, class Compute, class Pack, class Unpack>
  std::vector<Result> map(std::size_t n, const std::vector<double>& cost, Compute&& compute, Pack&& pack,
                          Unpack&& unpack) const {
    if (!distributed()) return compute(std::size_t{0}, n);
    const auto [first, last] = share(n, cost);
    std::vector<std::string> rows;
    {
      const std::vector<Result> mine = compute(first, last);
      rows.reserve(mine.size());
      for (const auto& r : mine) rows.push_back(pack(r));
    }
    rows = gather(std::move(rows));
    std::vector<Result> all;
    all.reserve(rows.size());
    for (const auto& row : rows) all.push_back(unpack(row));
    return all;
  }

  // The same for a trivially copyable Result: its bytes are the row.
  template <class Result, class Compute>
  std::vector<Result> map(std::size_t n, const std::vector<double>& cost, Compute&& compute) const {
    static_assert(std::is_trivially_copyable_v<Result>, "give pack and unpack for this Result");
    return map<Result>(
        n, cost, std::forward<Compute>(compute), [](const Result& r) { return std::move(RowWriter().put(r)).str(); },
        [](const std::string& row) {
          Result r;
          RowReader(row).get(r);
          return r;
        });
  }

 private:
  Sweep();
  int rank_ = 0, size_ = 1;
};

}  // namespace geomint
