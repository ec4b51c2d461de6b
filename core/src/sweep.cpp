#include "geomint/sweep.hpp"

#include <algorithm>
#include <climits>
#include <cstdint>
#include <cstdlib>
#include <numeric>
#include <stdexcept>

#ifdef GEOMINT_HAVE_MPI
#include <mpi.h>
#endif

namespace geomint {

namespace {

// A non-negative integer from the environment variable `name`, or -1 where it is unset or not one.
long env_count(const char* name) {
  const char* r = std::getenv(name);
  if (!r) return -1;
  char* end = nullptr;
  const long n = std::strtol(r, &end, 10);
  return end != r && *end == 0 && n >= 0 && n <= INT_MAX ? n : -1;
}

// Started by an MPI launcher with more than one process? (Open MPI's mpirun sets OMPI_COMM_WORLD_SIZE,
// MPICH/Hydra's mpiexec and Slurm's srun with PMI set PMI_SIZE.) A rank variable alone is no evidence: a script
// started from rank 1 of a job inherits PMI_RANK=1 and runs alone, and trusting it made that process a silent
// non-root that wrote nothing. A program run by hand (or by a launcher of one process) is a single process and
// never touches MPI: no start-up cost, no launcher needed, and nothing changes for make figures.
bool launched_by_mpi() {
  for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE"})
    if (env_count(v) > 1) return true;
  return false;
}

#ifdef GEOMINT_HAVE_MPI
void finalize_mpi() {
  int finalized = 0;
  MPI_Finalized(&finalized);
  if (!finalized) MPI_Finalize();
}
#endif

}  // namespace

bool Sweep::mpi_available() {
#ifdef GEOMINT_HAVE_MPI
  return true;
#else
  return false;
#endif
}

Sweep::Sweep() {
#ifdef GEOMINT_HAVE_MPI
  if (!launched_by_mpi()) return;
  int initialized = 0;
  MPI_Initialized(&initialized);
  if (!initialized) {
    MPI_Init(nullptr, nullptr);
    std::atexit(finalize_mpi);
  }
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
#else
  (void)launched_by_mpi;
#endif
}

int Sweep::launcher_rank() {
  static const int rank = [] {
    if (!launched_by_mpi()) return 0;
    for (const char* v : {"OMPI_COMM_WORLD_RANK", "PMIX_RANK", "PMI_RANK"})
      if (const long n = env_count(v); n >= 0) return static_cast<int>(n);
    return world().rank();
  }();
  return rank;
}

std::string Sweep::broadcast(const std::string& from_root) const {
  if (size_ <= 1) return from_root;
#ifdef GEOMINT_HAVE_MPI
  unsigned long long n = root() ? from_root.size() : 0;
  MPI_Bcast(&n, 1, MPI_UNSIGNED_LONG_LONG, 0, MPI_COMM_WORLD);
  std::string s = root() ? from_root : std::string(static_cast<std::size_t>(n), '\0');
  if (n > 0) MPI_Bcast(s.data(), static_cast<int>(n), MPI_CHAR, 0, MPI_COMM_WORLD);
  return s;
#else
  return from_root;
#endif
}

bool Sweep::started() {
#ifdef GEOMINT_HAVE_MPI
  int initialized = 0, finalized = 0, size = 1;
  MPI_Initialized(&initialized);
  MPI_Finalized(&finalized);
  if (!initialized || finalized) return false;
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  return size > 1;
#else
  return false;
#endif
}

void Sweep::abort_all(int status) {
#ifdef GEOMINT_HAVE_MPI
  if (started()) MPI_Abort(MPI_COMM_WORLD, status);
#else
  (void)status;
#endif
}

const Sweep& Sweep::world() {
  static const Sweep s;
  return s;
}

std::pair<std::size_t, std::size_t> Sweep::share_of(int rank, int size, std::size_t n, const std::vector<double>& cost) {
  if (size <= 1) return {0, n};
  if (!cost.empty() && cost.size() != n) throw std::invalid_argument("Sweep::share: cost must have n entries");
  // boundary of rank r: the first item whose cost before it reaches r/size of the total
  std::vector<double> before(n + 1, 0.0);
  for (std::size_t i = 0; i < n; ++i) before[i + 1] = before[i] + (cost.empty() ? 1.0 : std::max(0.0, cost[i]));
  auto boundary = [&](int r) -> std::size_t {
    if (r <= 0) return 0;
    if (r >= size) return n;
    const double target = before[n] * r / size;
    return static_cast<std::size_t>(std::lower_bound(before.begin(), before.end(), target) - before.begin());
  };
  const std::size_t first = std::min(n, boundary(rank)), last = std::min(n, boundary(rank + 1));
  return {first, std::max(first, last)};
}

std::vector<std::string> Sweep::gather(std::vector<std::string> mine) const {
  if (size_ <= 1) return mine;
#ifdef GEOMINT_HAVE_MPI
  // one buffer per rank: [row count][row sizes...][row bytes...]
  std::vector<std::uint64_t> head{mine.size()};
  std::uint64_t bytes = 0;
  for (const auto& r : mine) {
    head.push_back(r.size());
    bytes += r.size();
  }
  std::string buf(reinterpret_cast<const char*>(head.data()), head.size() * sizeof(std::uint64_t));
  buf.reserve(buf.size() + bytes);
  for (const auto& r : mine) buf += r;
  mine.clear();
  if (buf.size() > static_cast<std::size_t>(INT_MAX))
    throw std::runtime_error("Sweep::gather: more than 2 GB from one rank (split the sweep further)");
  int len = static_cast<int>(buf.size());
  std::vector<int> lens(root() ? static_cast<std::size_t>(size_) : 0), offs;
  MPI_Gather(&len, 1, MPI_INT, lens.data(), 1, MPI_INT, 0, MPI_COMM_WORLD);
  std::string all;
  if (root()) {
    offs.resize(lens.size());
    long long total = 0;
    for (std::size_t r = 0; r < lens.size(); ++r) {
      offs[r] = static_cast<int>(total);
      total += lens[r];
    }
    if (total > INT_MAX) throw std::runtime_error("Sweep::gather: more than 2 GB in all (split the sweep further)");
    all.resize(static_cast<std::size_t>(total));
  }
  MPI_Gatherv(buf.data(), len, MPI_CHAR, all.data(), lens.data(), offs.data(), MPI_CHAR, 0, MPI_COMM_WORLD);
  if (!root()) return {};
  std::vector<std::string> rows;
  for (std::size_t r = 0; r < lens.size(); ++r) {
    const char* p = all.data() + offs[r];
    std::uint64_t count = 0;
    std::memcpy(&count, p, sizeof count);
    std::vector<std::uint64_t> sizes(count);
    std::memcpy(sizes.data(), p + sizeof count, count * sizeof(std::uint64_t));
    const char* q = p + (count + 1) * sizeof(std::uint64_t);
    for (std::uint64_t k = 0; k < count; ++k) {
      rows.emplace_back(q, sizes[k]);
      q += sizes[k];
    }
  }
  return rows;
#else
  return mine;
#endif
}

void RowReader::check(std::size_t bytes) const {
  if (bytes > row_.size() - pos_) throw std::runtime_error("RowReader: row is shorter than what is read from it");
}

}  // namespace geomint
