// process.h — what every app test needs to run `sylva` as a user would: spawn a
// command, capture its stdout and stderr, its exit status or the signal that killed it,
// its peak memory; kill it when it hangs; and temporary folders that clean up.
//
// Header-only so that each tests/app/*_test.cpp includes the one implementation:
//   ProcessResult r = run_process({SYLVA_BINARY, "derive", "g.lsys"}, dir.path());
//   ASSERT_FALSE(crashed(r)) << describe(r);
//   EXPECT_EQ(r.exit_code, 1) << describe(r);
#pragma once

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <stdlib.h>
#include <sys/resource.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <system_error>
#include <thread>
#include <vector>

extern char** environ;

// How a child process ended and what it printed.
struct ProcessResult {
  int exit_code = -1;    // exit status if it exited; -1 if a signal ended it
  int signal = 0;        // the signal that ended it (SIGKILL after a timeout); 0 if it exited
  std::string out, err;  // everything it wrote to stdout / stderr
  long max_rss_kb = 0;   // peak resident memory in KiB (ru_maxrss of wait4); an upper
                         // bound: Linux starts a spawned child's peak at the parent's RSS
  bool timed_out = false;  // killed by run_process because it ran past timeout_s
  double wall_s = 0;       // seconds from spawn to exit
};

// How long a child may run before run_process kills it: a guard against a hang, not a time
// budget. Tests assert on the work done, never on seconds (docs/benchmarks.md measures
// time), so the guard is far above what any test takes on an idle machine (the longest
// child, the 10,000 bushes on llvmpipe, 13 s in release) to hold on a loaded or slow one.
inline constexpr int kHangSeconds = 600;

// Runs argv[0] (searched in PATH when it has no '/') with arguments argv[1..], in `cwd`
// (the current folder when empty), stdin from /dev/null, the caller's environment.
// A child still running after timeout_s seconds is killed with SIGKILL (timed_out set).
// Throws std::runtime_error when the program cannot be started at all.
inline ProcessResult run_process(const std::vector<std::string>& argv, const std::string& cwd = {},
                                 int timeout_s = kHangSeconds) {
  if (argv.empty()) throw std::invalid_argument("run_process: empty argv");
  auto fail = [&](const char* what, int error) {
    throw std::runtime_error(std::string("run_process(") + argv[0] + "): " + what + ": " +
                             std::strerror(error));
  };

  int out_pipe[2], err_pipe[2];
  if (pipe2(out_pipe, O_CLOEXEC) != 0) fail("pipe", errno);
  if (pipe2(err_pipe, O_CLOEXEC) != 0) {
    int error = errno;
    close(out_pipe[0]);
    close(out_pipe[1]);
    fail("pipe", error);
  }

  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  // dup2 clears close-on-exec on the copies; the originals close at exec.
  posix_spawn_file_actions_adddup2(&actions, out_pipe[1], STDOUT_FILENO);
  posix_spawn_file_actions_adddup2(&actions, err_pipe[1], STDERR_FILENO);
  if (!cwd.empty()) posix_spawn_file_actions_addchdir_np(&actions, cwd.c_str());

  // The child starts with default SIGPIPE handling and no blocked signals, whatever the
  // test runner set for itself.
  posix_spawnattr_t attributes;
  posix_spawnattr_init(&attributes);
  sigset_t no_signals, default_signals;
  sigemptyset(&no_signals);
  sigemptyset(&default_signals);
  sigaddset(&default_signals, SIGPIPE);
  posix_spawnattr_setsigmask(&attributes, &no_signals);
  posix_spawnattr_setsigdefault(&attributes, &default_signals);
  posix_spawnattr_setflags(&attributes, POSIX_SPAWN_SETSIGMASK | POSIX_SPAWN_SETSIGDEF);

  std::vector<char*> args;
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);

  const auto start = std::chrono::steady_clock::now();
  pid_t pid = 0;
  int spawn_error = posix_spawnp(&pid, argv[0].c_str(), &actions, &attributes, args.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  posix_spawnattr_destroy(&attributes);
  close(out_pipe[1]);
  close(err_pipe[1]);
  if (spawn_error != 0) {
    close(out_pipe[0]);
    close(err_pipe[0]);
    fail("spawn", spawn_error);
  }

  ProcessResult result;
  const auto deadline = start + std::chrono::seconds(timeout_s);
  auto kill_child = [&] {
    if (!result.timed_out) {
      kill(pid, SIGKILL);
      result.timed_out = true;
    }
  };

  // Read both pipes until both close, so a child filling one pipe never blocks on it.
  pollfd fds[2] = {{out_pipe[0], POLLIN, 0}, {err_pipe[0], POLLIN, 0}};
  std::string* sinks[2] = {&result.out, &result.err};
  int open_pipes = 2;
  std::vector<char> buffer(1 << 16);
  while (open_pipes > 0) {
    auto now = std::chrono::steady_clock::now();
    if (now >= deadline) {
      kill_child();
      // A killed child's pipes close at once; give up on them after a grace period in
      // case something it started still holds them.
      if (now >= deadline + std::chrono::seconds(5)) break;
    }
    auto wait = result.timed_out ? deadline + std::chrono::seconds(5) - now : deadline - now;
    int wait_ms = static_cast<int>(
        std::max<long long>(1, std::chrono::duration_cast<std::chrono::milliseconds>(wait).count()));
    int ready = poll(fds, 2, wait_ms);
    if (ready < 0) {
      if (errno == EINTR) continue;
      break;
    }
    for (int i = 0; i < 2; ++i) {
      if (fds[i].fd < 0 || fds[i].revents == 0) continue;
      ssize_t n = read(fds[i].fd, buffer.data(), buffer.size());
      if (n > 0) {
        sinks[i]->append(buffer.data(), static_cast<size_t>(n));
      } else if (n == 0 || (errno != EINTR && errno != EAGAIN)) {
        close(fds[i].fd);
        fds[i].fd = -1;
        --open_pipes;
      }
    }
  }
  for (pollfd& p : fds)
    if (p.fd >= 0) close(p.fd);

  // The child may close its output and keep running: the deadline still holds.
  int status = 0;
  rusage usage{};
  for (;;) {
    pid_t done = wait4(pid, &status, result.timed_out ? 0 : WNOHANG, &usage);
    if (done == pid) break;
    if (done < 0 && errno != EINTR) fail("wait4", errno);
    if (std::chrono::steady_clock::now() >= deadline)
      kill_child();
    else
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  result.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  result.max_rss_kb = usage.ru_maxrss;
  if (WIFEXITED(status)) {
    result.exit_code = WEXITSTATUS(status);
  } else if (WIFSIGNALED(status)) {
    result.signal = WTERMSIG(status);
  }
  return result;
}

#ifdef SYLVA_BINARY
// run_process with the sylva executable under test as argv[0].
inline ProcessResult run_sylva(const std::vector<std::string>& args, const std::string& cwd = {},
                               int timeout_s = kHangSeconds) {
  std::vector<std::string> argv{SYLVA_BINARY};
  argv.insert(argv.end(), args.begin(), args.end());
  return run_process(argv, cwd, timeout_s);
}
#endif

// True when stderr holds an AddressSanitizer / LeakSanitizer / UBSan report. Such a
// child exits with an ordinary status (often 1), so the status alone cannot show it.
inline bool sanitizer_report(const ProcessResult& r) {
  for (std::string_view marker : {"AddressSanitizer", "LeakSanitizer", "UndefinedBehaviorSanitizer",
                                  "ThreadSanitizer", ": runtime error: "}) {
    if (r.err.find(marker) != std::string::npos) return true;
  }
  return false;
}

// A crash in the widest sense: killed by a signal, hung, or a sanitizer report.
inline bool crashed(const ProcessResult& r) {
  return r.signal != 0 || r.timed_out || sanitizer_report(r);
}

// A short account of a run for failure messages: how it ended, then the start of its
// stderr and stdout (outputs can be megabytes).
inline std::string describe(const ProcessResult& r, size_t max_chars = 3000) {
  auto clip = [&](const std::string& s) {
    if (s.size() <= max_chars) return s;
    return s.substr(0, max_chars) + "\n... (" + std::to_string(s.size()) + " bytes in all)";
  };
  std::ostringstream text;
  if (r.timed_out)
    text << "TIMED OUT and killed after " << r.wall_s << " s";
  else if (r.signal != 0)
    text << "CRASHED: killed by signal " << r.signal << " (" << strsignal(r.signal) << ")";
  else
    text << "exit status " << r.exit_code;
  if (sanitizer_report(r)) text << " with a SANITIZER REPORT";
  text << ", " << r.wall_s << " s, peak RSS " << r.max_rss_kb << " KiB\n--- stderr ---\n"
       << clip(r.err) << "\n--- stdout ---\n" << clip(r.out) << "\n---";
  return text.str();
}

// Whole-file I/O for tests, binary-safe. read_file throws when the file cannot be read.
inline void write_file(const std::filesystem::path& path, std::string_view content) {
  std::ofstream file(path, std::ios::binary | std::ios::trunc);
  file.write(content.data(), static_cast<std::streamsize>(content.size()));
  if (!file.good()) throw std::runtime_error("write_file: cannot write " + path.string());
}

inline std::string read_file(const std::filesystem::path& path) {
  std::ifstream file(path, std::ios::binary);
  if (!file.is_open()) throw std::runtime_error("read_file: cannot read " + path.string());
  return std::string(std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>());
}

// Names of the entries of a folder, sorted.
inline std::vector<std::string> list_dir(const std::filesystem::path& folder) {
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(folder))
    names.push_back(entry.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

// A fresh, empty folder under $TMPDIR (or /tmp), removed with its contents at scope end.
class TempDir {
 public:
  TempDir() {
    std::string pattern = (std::filesystem::temp_directory_path() / "sylva-test-XXXXXX").string();
    if (mkdtemp(pattern.data()) == nullptr)
      throw std::runtime_error("TempDir: mkdtemp failed: " + std::string(std::strerror(errno)));
    path_ = pattern;
  }
  ~TempDir() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  const std::filesystem::path& path() const { return path_; }
  // Path of `name` inside the folder, as a string (for argv).
  std::string file(const std::string& name) const { return (path_ / name).string(); }
  // Writes `content` to `name` inside the folder and returns its path.
  std::string write(const std::string& name, std::string_view content) const {
    write_file(path_ / name, content);
    return file(name);
  }

 private:
  std::filesystem::path path_;
};
