#pragma once
// The outputs of one run: all new or all old, one run per output folder, and a killed run that heals.
//
// A run (OutputRun) owns its output folder <out> from prepare_output_dir (io.hpp) to its commit or discard:
//
// - Lock. <out>/.geomint-lock is held with flock(LOCK_EX) for the run's whole life. A second run into the same
//   folder refuses at once with one line naming the holder (process and host), exit 2, and leaves the folder as it
//   was. It refuses rather than waits: a run can take hours and a wait would look like a hang, and a second run
//   into a busy folder is almost always a mistake (two jobs given one --out) whose outputs would replace the
//   first's anyway. A lock file, not flock on the folder's descriptor: on NFS, where cluster runs write, Linux
//   emulates flock with POSIX locks, which need a descriptor open for writing, and a folder cannot be opened so.
//   The run removes the file when it ends (a run that locked a file another run removed meanwhile sees that the
//   folder's file is another one and tries again), so a finished run leaves nothing behind, and a killed one an
//   unlocked file that the next run takes over.
// - Staging. Every output is written into <out>/.geomint-run-XXXXXX (mode 0700: ours alone), each file created
//   relative to that folder's descriptor with O_CREAT|O_EXCL|O_NOFOLLOW: no symlink is followed and nothing
//   outside the folder is written; the final moves are renames relative to the two folders' descriptors, which
//   replace a symlink in <out> rather than write through it.
// - Commit, journaled. Each old file is kept as a hard link .old-<name> in the staging folder, then the list of
//   moves is written (.journal: written aside and renamed, so it is complete or absent), then the files are moved
//   into <out> one by one. A move that fails turns the journal into .journal-rollback and puts the old files back.
// - Healing. A killed run (SIGKILL, the OOM killer) leaves its staging folder. Every run holds the lock for its
//   whole life, so a staging folder seen by the run that holds the lock belongs to a run that is gone: that run
//   finishes the interrupted commit (.journal: every new file was complete), rolls it back (.journal-rollback), or
//   with no journal only removes the folder (the commit never began, <out> was never touched), and says so in one
//   line on stderr. Healing is idempotent: a run killed while healing is healed by the next one.
// - Signals. Every asynchronous terminating signal (SIGHUP, SIGINT, SIGQUIT, SIGTERM, SIGUSR1, SIGUSR2, SIGALRM,
//   SIGVTALRM, SIGPROF, SIGXCPU, SIGXFSZ, SIGIO, SIGPWR, SIGSTKFLT and the real-time signals) is an interrupt: the
//   staging folder and the lock are removed, a gnuplot drawing for the run is stopped, one line says so, and the
//   exit status is 128 + signal. Held (deferred) while the lock is taken, the folder healed, the run committed or
//   discarded, so those are never cut short by one. A signal ignored when the program starts (nohup, a background
//   job) stays ignored. Faults of the program itself (SIGSEGV, SIGABRT, ...) are crashes: the next run heals them.
//   Only SIGKILL (and a crash) needs the healing.
// - MPI. Only rank 0 starts a run; the writers (AtomicFile, TsvWriter, Figure::draw) refuse on any other rank.
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace geomint {

class OutputRun {
 public:
  static OutputRun* current();  // the active run of this process, or nullptr
  // Starts the run for target (an existing folder): takes the lock (InputError when another run holds it), heals
  // what killed runs left, creates the staging folder. Replaces (discards) an earlier uncommitted run of another
  // folder; returns the active run when it is this folder's.
  static OutputRun& start(const std::filesystem::path& target);

  const std::filesystem::path& target() const { return target_; }
  const std::filesystem::path& staging() const { return staging_; }
  int staging_fd() const { return stage_fd_; }
  // Where the file that will end as final_path is now: staging/<name> when final_path is in the target folder,
  // final_path itself otherwise (then it is not part of the run).
  std::filesystem::path staged(const std::filesystem::path& final_path) const;
  bool owns(const std::filesystem::path& final_path) const;
  // A new file in the staging folder for final_path, open for writing (O_CREAT|O_EXCL|O_NOFOLLOW, relative to the
  // staging folder's descriptor); its name there goes to `part`.
  int create_part(const std::filesystem::path& final_path, std::string& part);
  // staging/part (a file of ours there: create_part's, gnuplot's) becomes staging/<name of final_path>, complete:
  // it moves to final_path at commit.
  void place(const std::string& part, const std::filesystem::path& final_path);
  // Moves every complete file into place (journaled, interrupts held) and ends the run. Throws on the first move
  // that fails, after putting the old files back: the target ends all new or all old.
  void commit();
  // Removes the staging folder and everything in it and ends the run; the target is untouched.
  void discard();
  // A helper process (gnuplot) writing into the staging folder, stopped by the interrupt handler: pid > 0 when
  // it starts, -pid when it has ended (several may run at once).
  static void set_helper(long pid);
  // A process group the interrupt handler ends with the program (the compiler of a shape compiled at run time,
  // formula/jit.hpp, in a group of its own so that its children go with it): its id while it runs, 0 after.
  static void set_helper_group(long pgid);

 private:
  OutputRun() = default;
  void end();  // staging folder gone: release the lock and the descriptors
  std::filesystem::path target_, staging_;
  std::string staging_name_;
  int target_fd_ = -1, stage_fd_ = -1, lock_fd_ = -1;
  std::vector<std::string> names_;  // complete files, in the order they were placed
};

// Makes every asynchronous terminating signal an interrupt (see above) for the rest of the process; idempotent.
// guarded_main calls it on MPI rank 0 (the other ranks keep the default: they write nothing, and die silently).
void handle_interrupts();

// The run is over and has said so: its outputs are in their final state and its line (if any) is written. An
// interrupt from now on (an MPI launcher ending the job because another rank already exited with this status, a
// user's Ctrl-C during MPI_Finalize) has nothing to undo and nothing true to add: the process exits with `status`,
// silently. `report` (the run's last line, if any) runs first, with interrupts held: one arriving while it writes
// is acted on after it, as the silent exit. guarded_main calls it on every way out.
void interrupts_after_outcome(int status, const std::function<void()>& report = {});

// Throws std::logic_error unless this process is MPI rank 0 (or no MPI launcher started it): what every writer
// checks before it creates anything.
void require_output_rank(const std::filesystem::path& what);

}  // namespace geomint
