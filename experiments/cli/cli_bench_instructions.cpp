/// \file
/// `hexrefine bench --instructions`: the instruction count of every workload of the
/// instruction_workloads driver (experiments/bench/instruction_workloads.cpp), counted by
/// Valgrind, written as one JSON file that `bench-compare --gate instructions` compares.
///
/// Why instructions: on the shared 2-core machines this project runs on, the same smoke run's
/// times vary by up to 2x from run to run; the number of instructions a workload executes does
/// not depend on the load, so a 3 % growth of it is a real change of the code's work (as SQLite
/// tracks its performance by Cachegrind's counts). It does not see cache misses or page faults:
/// the wall-time suite (`bench`, `bench --history`) stays for those.
///
/// Choices:
/// - The tool is Callgrind, whose Ir (instructions executed) is the count Cachegrind reports,
///   because it can count one function only: `--collect-atstart=no
///   --toggle-collect=hexrefine_instruction_region`, the driver's measured region (the workload's
///   work, without building its input, the program's start or its exit). Cachegrind cannot in
///   Debian 12's Valgrind 3.19 (its start/stop client requests came with 3.22).
/// - One Valgrind process per workload, so that no workload's count depends on another's heap
///   or lazily built tables; `--jobs N` (default 2) run at once (the counts do not depend on
///   it). Each runs with an empty environment but HEXREFINE_SHARED_DIR, which names a link to
///   the shared folder at a path of fixed length, in its own folder (also of fixed length),
///   ignoring ~/.valgrindrc (`--command-line-only=yes`): neither the caller's variables
///   (GLIBC_TUNABLES, which this binary sets for huge pages, TMPDIR) nor the length of a path
///   reach the count (a path's length moves the heap's layout, and the alignment of a copied
///   buffer changes the steps of memcpy: about a hundred instructions). Where allowed, each is
///   pid 1 of a pid namespace of its own, so that the pid the writers put into their temporary
///   file names is as long in every run.
/// - The JSON: "format" ("hexrefine-instructions"), "version" (1), "context" (date, commit,
///   whether the work tree had changes, host, tool, Valgrind's version, the compiler the driver
///   was built with, jobs, wall seconds of the run) and "benchmarks", in the driver's order:
///   per workload its identity (name, operation, case, size, method, placement, format,
///   threads, description), "instructions" and "work" (the driver's counts of what was done).
#include <fcntl.h>
#include <sched.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <iterator>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "experiments/cli/cli_bench.hpp"
#include "mesh/atomic_file.hpp"
#include "mesh/error.hpp"

namespace hexrefine {

namespace {

using nlohmann::json;

/// The symbol of the driver's measured region (instruction_workloads.cpp).
constexpr const char* region_symbol = "hexrefine_instruction_region";

std::string file_text(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

/// The last `lines` lines of `text`.
std::string text_tail(const std::string& text, int lines) {
  size_t at = text.size();
  for (int i = 0; i <= lines && at > 0; ++i) {
    const size_t nl = text.rfind('\n', at - 1);
    if (nl == std::string::npos) return text;
    at = nl;
    if (i == lines) return text.substr(nl + 1);
  }
  return text;
}

/// `name` in PATH (or /usr/bin:/bin when PATH is unset), as an absolute path; empty if absent.
std::filesystem::path executable_in_path(const std::string& name) {
  const char* path = std::getenv("PATH");
  std::istringstream dirs(path ? path : "/usr/bin:/bin");
  std::string dir;
  while (std::getline(dirs, dir, ':')) {
    if (dir.empty()) continue;
    const std::filesystem::path candidate = std::filesystem::path(dir) / name;
    if (access(candidate.c_str(), X_OK) == 0) return std::filesystem::absolute(candidate);
  }
  return {};
}

/// Enters a new pid namespace (as root, or through a new user namespace where unprivileged ones
/// are allowed): the next child forked is its pid 1. False where neither is allowed.
bool process_enter_pid_namespace() {
  return unshare(CLONE_NEWPID) == 0 || unshare(CLONE_NEWUSER | CLONE_NEWPID) == 0;
}

/// Starts `argv` in folder `cwd` with environment `env`, stdout and stderr to `output`; with
/// `pid_one`, as pid 1 of a pid namespace of its own (the started process waits for it and
/// exits with its code; it dies with that process). Returns the child's pid; OperationError if
/// it cannot be started.
pid_t process_start(const std::vector<std::string>& argv, const std::vector<std::string>& env,
                    const std::filesystem::path& cwd, const std::filesystem::path& output,
                    bool pid_one = false) {
  std::vector<char*> args, envp;
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  for (const std::string& e : env) envp.push_back(const_cast<char*>(e.c_str()));
  envp.push_back(nullptr);
  const pid_t pid = fork();
  if (pid < 0) throw OperationError("hexrefine bench: cannot start " + argv[0]);
  if (pid == 0) {
    if (pid_one) {
      if (!process_enter_pid_namespace()) _exit(126);
      const pid_t inner = fork();
      if (inner < 0) _exit(127);
      if (inner > 0) {
        int status = 0;
        while (waitpid(inner, &status, 0) < 0)
          if (errno != EINTR) _exit(127);
        _exit(WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status));
      }
      prctl(PR_SET_PDEATHSIG, SIGKILL);
    }
    const int fd = open(output.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd < 0 || chdir(cwd.c_str()) != 0) _exit(127);
    dup2(fd, 1);
    dup2(fd, 2);
    close(fd);
    execve(args[0], args.data(), envp.data());
    _exit(127);
  }
  return pid;
}

/// Whether this process may start workloads as pid 1 of their own pid namespace (a child tries).
bool pid_namespaces_allowed() {
  const pid_t pid = fork();
  if (pid < 0) return false;
  if (pid == 0) _exit(process_enter_pid_namespace() ? 0 : 1);
  int status = 0;
  while (waitpid(pid, &status, 0) < 0)
    if (errno != EINTR) return false;
  return WIFEXITED(status) && WEXITSTATUS(status) == 0;
}

/// Waits for `pid`; its exit code (128 + signal when killed).
int process_wait(pid_t pid) {
  int status = 0;
  while (waitpid(pid, &status, 0) < 0)
    if (errno != EINTR) return -1;
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

/// The "totals:" (or, from older Valgrinds, "summary:") figure of a Callgrind output file: the
/// instructions collected. OperationError naming the file if there is none.
long long callgrind_total(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw OperationError("hexrefine bench: no Callgrind output " + path.string());
  std::string line;
  long long total = -1;
  while (std::getline(in, line)) {
    for (const char* key : {"totals:", "summary:"}) {
      if (line.rfind(key, 0) != 0) continue;
      std::istringstream s(line.substr(std::char_traits<char>::length(key)));
      long long v = -1;
      if (s >> v) total = v;
    }
  }
  if (total < 0)
    throw OperationError("hexrefine bench: " + path.string() + ": no \"totals:\" line");
  return total;
}

/// The first line of `command`'s output, or "unknown" if it fails (no git, not a checkout).
std::string first_line_of(const std::string& command) {
  FILE* pipe = popen((command + " 2>/dev/null").c_str(), "r");
  if (!pipe) return "unknown";
  char buffer[256] = {};
  std::string line;
  if (fgets(buffer, sizeof buffer, pipe)) line = buffer;
  const int status = pclose(pipe);
  while (!line.empty() && (line.back() == '\n' || line.back() == '\r')) line.pop_back();
  return status != 0 || line.empty() ? "unknown" : line;
}

/// One workload's run: its process, files and start time.
struct Running {
  size_t index;
  std::chrono::steady_clock::time_point start;
};

}  // namespace

int bench_instructions_run(const CliArgs& a) {
  if (!a.positional.empty())
    throw InputError("hexrefine bench: unexpected argument '" + a.positional[0] + "'");
  for (const char* other : {"--smoke", "--repetitions", "--history"})
    if (a.flag(other) || a.value(other))
      throw InputError(std::string("hexrefine bench: --instructions counts one run of each "
                                   "workload; ") +
                       other + " is for the timed suite");
  int jobs = 2;
  if (const auto j = a.value("--jobs"))
    jobs = static_cast<int>(cli_parse_int_in(*j, 1, 64, "hexrefine bench --jobs"));
  std::optional<std::regex> filter;
  if (const auto f = a.value("--filter")) {
    if (f->empty()) throw InputError("hexrefine bench: --filter needs a non-empty regex");
    try {
      filter.emplace(*f);
    } catch (const std::regex_error& e) {
      throw InputError("hexrefine bench: --filter '" + *f + "': " + e.what());
    }
  }

  std::error_code ec;
  const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (ec) throw OperationError("hexrefine bench: cannot locate the hexrefine binary");
  const std::filesystem::path driver = self.parent_path() / "instruction_workloads";
  if (access(driver.c_str(), X_OK) != 0)
    throw OperationError("hexrefine bench: no " + driver.string() +
                         " (configure with -DHEXREFINE_BENCHMARKS=ON and build it)");
  const std::filesystem::path valgrind = executable_in_path("valgrind");
  if (valgrind.empty())
    throw OperationError(
        "hexrefine bench --instructions: valgrind not found in PATH (Debian: apt-get install "
        "valgrind; .ci/setup.sh installs it)");

  // The shared folder as the benchmarks find it (bench_util.hpp): HEXREFINE_SHARED_DIR, else
  // beside the source tree of the build folder.
  const char* shared_variable = std::getenv("HEXREFINE_SHARED_DIR");
  const std::filesystem::path shared = std::filesystem::absolute(
      shared_variable ? std::filesystem::path(shared_variable)
                      : (self.parent_path() / "../../../shared").lexically_normal());
  if (!std::filesystem::exists(shared / "meshes" / "rockerarm.mesh"))
    throw OperationError("hexrefine bench --instructions: no " +
                         (shared / "meshes" / "rockerarm.mesh").string() +
                         " (set HEXREFINE_SHARED_DIR to the shared/ folder)");

  char scratch_template[] = "/tmp/hexrefine_bench_instructions_XXXXXX";
  if (!mkdtemp(scratch_template))
    throw OperationError("hexrefine bench: cannot create a folder in /tmp");
  const std::filesystem::path scratch = scratch_template;
  struct Cleanup {
    std::filesystem::path dir;
    ~Cleanup() {
      std::error_code e;
      std::filesystem::remove_all(dir, e);
    }
  } cleanup{scratch};
  // The driver finds the meshes through a link of a fixed path length: the strings it builds
  // from the path, hence the heap's layout and the alignment of the buffers the workloads copy,
  // are the same whatever the checkout's location.
  std::filesystem::create_directory_symlink(shared, scratch / "shared", ec);
  if (ec)
    throw OperationError("hexrefine bench: cannot link " + shared.string() + ": " + ec.message());
  const std::vector<std::string> env = {"HEXREFINE_SHARED_DIR=" + (scratch / "shared").string()};

  // The workloads, in the driver's order.
  const std::filesystem::path list_output = scratch / "list.txt";
  if (process_wait(process_start({driver.string(), "--list"}, env, scratch, list_output)) != 0)
    throw OperationError("hexrefine bench: instruction_workloads --list failed: " +
                         file_text(list_output));
  std::vector<std::string> names;
  {
    std::istringstream lines(file_text(list_output));
    std::string name;
    while (std::getline(lines, name))
      if (!name.empty() && (!filter || std::regex_search(name, *filter))) names.push_back(name);
  }
  if (names.empty()) throw OperationError("hexrefine bench: no workload matches --filter");
  const std::string valgrind_version = first_line_of("'" + valgrind.string() + "' --version");

  // Writers name their temporary files after the process id, so a pid with another number of
  // digits moves a writer's count (about 330 instructions a digit: 0.05 % of the VTU writer's
  // 1.8 million from 4 digits to 1; results/bench/instructions_pid_digits.json). As pid 1 of a
  // namespace of its own every workload has the same pid in every run.
  const bool pid_one = pid_namespaces_allowed();
  if (!pid_one)
    std::cerr << "hexrefine bench: no pid namespaces here (unshare refused): the writers' counts "
                 "may differ by a few hundred instructions with the pid's length\n";

  // Up to `jobs` Valgrind processes at once, each workload in a folder of its own.
  const auto started = std::chrono::steady_clock::now();
  std::vector<json> results(names.size());
  std::map<pid_t, Running> running;
  size_t next = 0, done = 0;
  // Folder names of one length (000, 001, ...): the result path is an argument of the driver.
  auto folder = [&](size_t i) {
    std::string digits = std::to_string(i);
    return scratch / (std::string(3 - std::min<size_t>(3, digits.size()), '0') + digits);
  };
  while (done < names.size()) {
    while (next < names.size() && static_cast<int>(running.size()) < jobs) {
      const std::filesystem::path dir = folder(next);
      std::filesystem::create_directories(dir);
      const std::vector<std::string> argv = {valgrind.string(),
                                             "--command-line-only=yes",
                                             "--tool=callgrind",
                                             "--collect-atstart=no",
                                             std::string("--toggle-collect=") + region_symbol,
                                             "--dump-line=no",
                                             "--callgrind-out-file=" + (dir / "cg.out").string(),
                                             driver.string(),
                                             "--run",
                                             names[next],
                                             "--result",
                                             (dir / "result.json").string()};
      const pid_t pid = process_start(argv, env, dir, dir / "output.txt", pid_one);
      running[pid] = {next, std::chrono::steady_clock::now()};
      ++next;
    }
    int status = 0;
    const pid_t pid = waitpid(-1, &status, 0);
    if (pid < 0) {
      if (errno == EINTR) continue;
      throw OperationError("hexrefine bench: lost track of the Valgrind processes");
    }
    const auto it = running.find(pid);
    if (it == running.end()) continue;
    const Running r = it->second;
    running.erase(it);
    ++done;
    const std::filesystem::path dir = folder(r.index);
    const int code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    if (code != 0) {
      for (const auto& [other, _] : running) kill(other, SIGTERM);
      for (const auto& [other, _] : running) process_wait(other);
      throw OperationError("hexrefine bench: workload " + names[r.index] + " failed (exit " +
                           std::to_string(code) + "):\n" +
                           text_tail(file_text(dir / "output.txt"), 12));
    }
    json result;
    try {
      result = json::parse(file_text(dir / "result.json"));
    } catch (const json::exception& e) {
      throw OperationError("hexrefine bench: workload " + names[r.index] +
                           " wrote no result: " + e.what());
    }
    const long long instructions = callgrind_total(dir / "cg.out");
    if (instructions <= 0)
      throw OperationError("hexrefine bench: workload " + names[r.index] +
                           ": no instruction counted (is " + region_symbol +
                           " in the driver's symbol table? a stripped binary hides it)");
    result["instructions"] = instructions;
    results[r.index] = std::move(result);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - r.start).count();
    std::cerr << "hexrefine bench: [" << done << "/" << names.size() << "] " << names[r.index]
              << ": " << digits_grouped(instructions) << " instructions (" << std::fixed
              << std::setprecision(1) << seconds << " s under Callgrind)\n";
  }
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();

  json context;
  const std::time_t now = std::time(nullptr);
  char date[32];
  std::strftime(date, sizeof date, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&now));
  context["date"] = date;
  context["commit"] = first_line_of("git rev-parse HEAD");
  // Changes to the code, not to results/ (where this file itself usually goes).
  context["dirty"] = first_line_of(
                         "git status --porcelain --untracked-files=no -- ':/' "
                         "':(top,exclude)results'") != "unknown";
  char host[256] = {};
  gethostname(host, sizeof host - 1);
  context["host"] = host;
  context["tool"] = "callgrind";
  context["valgrind"] = valgrind_version;
  context["compiler"] = results.front().value("compiler", std::string("unknown"));
  context["jobs"] = jobs;
  context["pid_namespace"] = pid_one;
  context["wall_seconds"] = std::round(wall * 10) / 10;
  if (filter) context["filter"] = *a.value("--filter");
  for (json& r : results) r.erase("compiler");
  const json doc = {{"format", "hexrefine-instructions"},
                    {"version", 1},
                    {"context", context},
                    {"benchmarks", results}};
  const std::string text = doc.dump(2) + "\n";
  if (const auto out = a.value("--out")) {
    file_write_atomically(*out, [&](std::ostream& os) { os << text; });
    std::cerr << "hexrefine bench: " << results.size() << " instruction counts written to " << *out
              << " (" << std::fixed << std::setprecision(1) << wall << " s)\n";
  } else {
    std::cout << text;
  }
  return 0;
}

}  // namespace hexrefine
