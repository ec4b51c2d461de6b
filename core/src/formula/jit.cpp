#include "geomint/formula/jit.hpp"

#include <dlfcn.h>
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "geomint/error.hpp"
#include "geomint/interrupt.hpp"
#include "geomint/output_run.hpp"

extern char** environ;

namespace geomint::formula::jit {

// Written by the build (core/src/formula/jit_config.cpp.in): where the sources and the recorded flags are.
namespace config {
extern const char* const source_dir;
extern const char* const flags_file;
extern const char* const default_cache;
}  // namespace config

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return {};
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// The build's recorded compiler and flags (generated/jit/flags.txt: the compiler, then one argument per line, then
// "--link--" and the link's, then "--formulas--" and the formulas' libraries).
struct Flags {
  std::string compiler;
  std::vector<std::string> compile, link, formulas;
  std::string text;
};

bool read_flags(Flags& f, std::string* why) {
  f.text = read_text(config::flags_file);
  if (f.text.empty()) {
    if (why) *why = std::string("the build's record of its compiler and flags (") + config::flags_file + ") is not there";
    return false;
  }
  std::istringstream in(f.text);
  std::string line;
  std::vector<std::string>* into = nullptr;
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    if (f.compiler.empty()) {
      f.compiler = line;
      into = &f.compile;
    } else if (line == "--link--") {
      into = &f.link;
    } else if (line == "--formulas--") {
      into = &f.formulas;
    } else if (line != "-Werror") {  // a shape's code is the build's, checked there; a warning here stops nothing
      into->push_back(line);
    }
  }
  if (f.compiler.empty() || ::access(f.compiler.c_str(), X_OK) != 0) {
    if (why) *why = "the build's compiler (" + f.compiler + ") is not there to run";
    return false;
  }
  return true;
}

std::string number(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.0f", x);
  return buf;
}

// The files a dependency list (the compiler's -MF output, make syntax) names after its target.
std::vector<std::string> dependencies(const std::string& depfile) {
  const std::string text = read_text(depfile);
  std::vector<std::string> out;
  const std::size_t colon = text.find(": ");
  if (colon == std::string::npos) return out;
  std::string word;
  for (std::size_t i = colon + 2; i < text.size(); ++i) {
    const char c = text[i];
    if (c == '\\' && i + 1 < text.size() && text[i + 1] == '\n') {
      ++i;
    } else if (c == '\\' && i + 1 < text.size() && text[i + 1] == ' ') {
      word += ' ';
      ++i;
    } else if (c == ' ' || c == '\n' || c == '\t') {
      if (!word.empty()) out.push_back(word);
      word.clear();
    } else {
      word += c;
    }
  }
  if (!word.empty()) out.push_back(word);
  return out;
}

bool modified_time(const std::string& path, struct timespec& t) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return false;
  t = st.st_mtim;
  return true;
}

bool newer(const struct timespec& a, const struct timespec& b) {
  return a.tv_sec > b.tv_sec || (a.tv_sec == b.tv_sec && a.tv_nsec > b.tv_nsec);
}

// The object is the one these flags and sources make, and nothing it included changed since.
bool fresh(const std::string& object, const std::string& stamp, const std::string& expected, std::size_t units) {
  struct timespec built {};
  if (!modified_time(object, built) || read_text(stamp) != expected) return false;
  for (std::size_t i = 0; i < units; ++i) {
    const auto deps = dependencies(object.substr(0, object.size() - 3) + "." + std::to_string(i) + ".d");
    if (deps.empty()) return false;
    for (const auto& d : deps) {
      struct timespec t {};
      if (!modified_time(d, t) || newer(t, built)) return false;
    }
  }
  return true;
}

void write_text(const std::string& path, const std::string& text) {
  const std::string tmp = path + "." + std::to_string(::getpid()) + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    out << text;
    if (!out.flush()) throw std::runtime_error("cannot write " + tmp);
  }
  fs::rename(tmp, path);
}

// Polls the caller's watch (the Python module's Ctrl-C) while a child runs or a lock waits.
void wait_a_little() {
  Watch::poll_now();
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
}

// A child process, started with an argument vector (no shell), its output to `log`, in the process group `group`
// (0: a new group, its own). The compiler's driver does not pass a SIGTERM on to the compiler proper it runs, so the
// children are stopped by their group, and a program's interrupt handler ends that group with the program.
class Child {
 public:
  Child(const std::vector<std::string>& args, const std::string& log, pid_t group) {
    std::vector<char*> argv;
    for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_adddup2(&actions, 1, 2);
    posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
    posix_spawnattr_t attributes;
    posix_spawnattr_init(&attributes);
    posix_spawnattr_setflags(&attributes, POSIX_SPAWN_SETPGROUP);
    posix_spawnattr_setpgroup(&attributes, group);
    const int rc = posix_spawn(&pid_, argv[0], &actions, &attributes, argv.data(), environ);
    posix_spawnattr_destroy(&attributes);
    posix_spawn_file_actions_destroy(&actions);
    if (rc != 0) throw std::runtime_error("cannot start " + args[0] + ": " + std::strerror(rc));
    group_ = group == 0 ? pid_ : group;
  }
  ~Child() {
    if (pid_ > 0) {  // left while running (interrupted, or another unit failed): it and what it started
      ::kill(-group_, SIGTERM);
      int status = 0;
      ::waitpid(pid_, &status, 0);
    }
  }
  Child(const Child&) = delete;
  Child& operator=(const Child&) = delete;
  pid_t pid() const { return pid_; }
  // The exit status once it ended, -1 while it runs; a signal that ended it as 128 + its number.
  int poll() {
    if (pid_ <= 0) return status_;
    int status = 0;
    const pid_t r = ::waitpid(pid_, &status, WNOHANG);
    if (r == 0) return -1;
    pid_ = 0;
    status_ = r < 0 ? 127 : WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    return status_;
  }

 private:
  pid_t pid_ = 0, group_ = 0;
  int status_ = -1;
};

// The lock that makes processes wanting the same object take turns (released when the process ends, too).
class Lock {
 public:
  Lock(const std::string& path, const std::string& what) {
    fd_ = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd_ < 0) throw std::runtime_error("cannot open the lock " + path + ": " + std::strerror(errno));
    bool said = false;
    while (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
      if (errno != EWOULDBLOCK && errno != EINTR) throw std::runtime_error("cannot lock " + path + ": " + std::strerror(errno));
      if (!said) std::cerr << "geomint: waiting for another process compiling " << what << " (" << path << ")\n";
      said = true;
      try {
        wait_a_little();
      } catch (...) {
        ::close(fd_);
        throw;
      }
    }
  }
  ~Lock() { ::close(fd_); }
  Lock(const Lock&) = delete;
  Lock& operator=(const Lock&) = delete;

 private:
  int fd_ = -1;
};

std::string generate(const Unit& u) {
  const std::string path = std::string(config::source_dir) + "/" + u.template_file;
  std::string text = read_text(path);
  if (text.empty()) throw std::runtime_error("the source " + path + " of a shape compiled at run time is not there");
  for (const auto& [key, value] : u.substitutions) {
    const std::string at = "@" + key + "@";
    for (std::size_t p = text.find(at); p != std::string::npos; p = text.find(at, p + value.size()))
      text.replace(p, at.size(), value);
  }
  return "// Generated by geomint at run time (core/src/formula/jit.cpp) from " + u.template_file + "\n" + text + u.appended;
}

std::string tail(const std::string& log, std::size_t lines) {
  const std::string text = read_text(log);
  std::size_t p = text.size();
  for (std::size_t k = 0; k <= lines && p > 0; ++k) p = text.rfind('\n', p - 1);
  return p == std::string::npos ? text : text.substr(p + 1);
}

// Runs the commands at once (a shape's units are independent) and waits for all; the first failure throws (and the
// others are stopped).
void run_all(std::vector<std::vector<std::string>> commands, const std::vector<std::string>& logs, const std::string& what,
             Task& task) {
  std::vector<std::unique_ptr<Child>> children;
  struct Registered {  // the group, for a program's interrupt handler, while the children run
    ~Registered() { OutputRun::set_helper_group(0); }
  } registered;
  pid_t group = 0;
  for (std::size_t i = 0; i < commands.size(); ++i) {
    children.push_back(std::make_unique<Child>(commands[i], logs[i], group));
    if (group == 0) OutputRun::set_helper_group(group = children.back()->pid());
  }
  std::vector<int> status(children.size(), -1);
  for (std::size_t left = children.size(); left > 0;) {
    for (std::size_t i = 0; i < children.size(); ++i) {
      if (status[i] >= 0) continue;
      status[i] = children[i]->poll();
      if (status[i] < 0) continue;
      --left;
      task.add();
      if (status[i] != 0)
        throw std::runtime_error("compiling " + what + " failed (the compiler's exit status " + std::to_string(status[i]) +
                                 "; its log: " + logs[i] + "):\n" + tail(logs[i], 12));
    }
    if (left > 0) wait_a_little();
  }
}

// Makes the object holding this code global, so that a shared object loaded next resolves the core's functions
// against it: a program's (linked with -rdynamic) already is; the Python module is loaded local by the interpreter.
void make_this_object_global() {
  static std::once_flag once;
  std::call_once(once, [] {
    Dl_info info{};
    if (::dladdr(reinterpret_cast<void*>(&make_this_object_global), &info) != 0 && info.dli_fname != nullptr)
      (void)::dlopen(info.dli_fname, RTLD_NOW | RTLD_NOLOAD | RTLD_GLOBAL);  // null for the program itself: global already
  });
}

}  // namespace

std::string cache_directory() {
  const char* env = std::getenv("GEOMINT_SHAPE_CACHE");
  return env != nullptr && *env != '\0' ? std::string(env) : std::string(config::default_cache);
}

bool enabled(std::string* why) {
  const char* env = std::getenv("GEOMINT_SHAPE_JIT");
  if (env != nullptr && std::string(env) == "0") {
    if (why) *why = "compiling shapes at run time is off (GEOMINT_SHAPE_JIT=0)";
    return false;
  }
  Flags f;
  return read_flags(f, why);
}

void* symbol(const Library& library, const std::string& name) {
  static std::mutex mutex;
  static std::map<std::string, void*> loaded;
  const std::lock_guard<std::mutex> guard(mutex);
  void*& handle = loaded[library.name];
  if (handle == nullptr) {
    std::string why;
    Flags flags;
    if (!enabled(&why) || !read_flags(flags, &why)) throw InputError(library.what + " is not compiled in this build, and " + why);
    const fs::path dir = cache_directory();
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (ec) throw std::runtime_error("cannot make the shape cache " + dir.string() + ": " + ec.message());
    const std::string stem = (dir / library.name).string();
    const std::string object = stem + ".so", stamp = stem + ".stamp";
    std::vector<std::string> sources;
    std::string expected = flags.text;
    for (const auto& u : library.units) {
      sources.push_back(generate(u));
      expected += "\n--unit--\n" + sources.back();
      for (const auto& o : u.options) expected += "\n" + o;
    }
    const Lock lock(stem + ".lock", library.what);
    if (!fresh(object, stamp, expected, library.units.size())) {
      const auto start = Clock::now();
      std::cerr << "geomint: compiling " << library.what << " for its first use with this build (about a minute of one "
                << "core per unit, " << library.units.size() << " units; kept in " << dir.string() << ")" << std::endl;
      Task task("compiling " + library.what, "steps", static_cast<double>(library.units.size() + 1));
      const std::string pid = std::to_string(::getpid());
      std::vector<std::vector<std::string>> compiles;
      std::vector<std::string> logs, objects, depfiles;
      for (std::size_t i = 0; i < library.units.size(); ++i) {
        const std::string base = stem + "." + std::to_string(i);
        write_text(base + ".cpp", sources[i]);
        objects.push_back(base + "." + pid + ".o");
        depfiles.push_back(base + "." + pid + ".d");
        logs.push_back(base + ".log");
        std::vector<std::string> args{flags.compiler};
        args.insert(args.end(), flags.compile.begin(), flags.compile.end());
        // What the object defines stays its own (its entry points say otherwise): its code binds to its own
        // instances of the templates, not to a program's of the same name, and the loader resolves only what it
        // takes from the program.
        args.insert(args.end(), {"-fvisibility=hidden", "-fvisibility-inlines-hidden"});
        args.insert(args.end(), library.units[i].options.begin(), library.units[i].options.end());
        args.insert(args.end(), {"-MD", "-MF", depfiles.back(), "-c", base + ".cpp", "-o", objects.back()});
        compiles.push_back(std::move(args));
      }
      struct Cleanup {
        std::vector<std::string> files;
        ~Cleanup() {
          for (const auto& f : files) ::unlink(f.c_str());
        }
      } cleanup{objects};
      cleanup.files.insert(cleanup.files.end(), depfiles.begin(), depfiles.end());
      run_all(compiles, logs, library.what, task);
      const std::string linked = stem + "." + pid + ".so";
      cleanup.files.push_back(linked);
      std::vector<std::string> link{flags.compiler, "-shared", "-o", linked};
      link.insert(link.end(), objects.begin(), objects.end());
      link.insert(link.end(), flags.link.begin(), flags.link.end());
      if (library.links_formulas) link.insert(link.end(), flags.formulas.begin(), flags.formulas.end());
      run_all({link}, {stem + ".link.log"}, library.what, task);
      for (std::size_t i = 0; i < depfiles.size(); ++i) fs::rename(depfiles[i], stem + "." + std::to_string(i) + ".d");
      fs::rename(linked, object);
      write_text(stamp, expected);
      const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
      std::cerr << "geomint: compiled " << library.what << " in " << number(seconds) << " s (" << object << ")" << std::endl;
    }
    make_this_object_global();
    handle = ::dlopen(object.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (handle == nullptr) {
      const char* err = ::dlerror();
      throw std::runtime_error("cannot load " + library.what + " (" + object + "): " + (err ? err : "dlopen failed") +
                               " (a program that loads shapes exports its symbols: link it with -rdynamic, CMake's "
                               "ENABLE_EXPORTS)");
    }
  }
  void* s = ::dlsym(handle, name.c_str());
  if (s == nullptr) throw std::runtime_error("the compiled " + library.what + " has no " + name);
  return s;
}

}  // namespace geomint::formula::jit
