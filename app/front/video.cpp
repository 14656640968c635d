// video.cpp — see video.h.
#include "app/front/video.h"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <vector>

#include "app/front/batch.h"
#include "core/util/file_io.h"

extern char** environ;

namespace sylva::cli {

std::optional<std::string> find_ffmpeg() {
  const char* path = std::getenv("PATH");
  if (!path) return std::nullopt;
  std::string dirs(path);
  size_t start = 0;
  for (;;) {
    const size_t colon = dirs.find(':', start);
    std::string dir = dirs.substr(start, colon == std::string::npos ? std::string::npos : colon - start);
    if (dir.empty()) dir = ".";
    const std::string candidate = dir + "/ffmpeg";
    if (::access(candidate.c_str(), X_OK) == 0 && std::filesystem::is_regular_file(candidate)) return candidate;
    if (colon == std::string::npos) return std::nullopt;
    start = colon + 1;
  }
}

std::optional<std::string> video_container_for(const std::string& video) {
  std::string ext = std::filesystem::path(video).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (ext == ".mp4") return "mp4";
  if (ext == ".mkv") return "matroska";
  if (ext == ".webm") return "webm";
  if (ext == ".mov") return "mov";
  if (ext == ".gif") return "gif";
  return std::nullopt;
}

std::string ffmpeg_sequence_pattern(const std::string& pattern) {
  static constexpr std::string_view kFrame = "{frame}";
  std::string out;
  for (size_t i = 0; i < pattern.size();) {
    if (pattern.compare(i, kFrame.size(), kFrame) == 0) {
      out += "%0" + std::to_string(kFramePatternDigits) + "d";
      i += kFrame.size();
    } else {
      if (pattern[i] == '%') out += '%';
      out += pattern[i++];
    }
  }
  return out;
}

namespace {

std::string number_text(double x) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.17g", x);
  return buf;
}

// Runs argv[0] with `argv`, stdin from /dev/null, stdout discarded, stderr captured into
// *err. Returns the exit status (128 + signal when killed, -1 when it could not start).
// The child is stopped (SIGTERM) when `cancel` becomes true while it runs — sylva's SIGINT
// handler sets it, and interrupts the read below — and by a SIGTERM or SIGHUP to sylva
// (remember_child): it never outlives sylva.
int run_child(const std::vector<std::string>& argv, std::string* err, const std::atomic<bool>* cancel) {
  int pipe_fds[2];
  if (::pipe(pipe_fds) != 0) return -1;
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_adddup2(&actions, pipe_fds[1], 2);
  posix_spawn_file_actions_addclose(&actions, pipe_fds[0]);
  posix_spawn_file_actions_addclose(&actions, pipe_fds[1]);
  std::vector<char*> args;
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  pid_t pid = 0;
  const int spawned = posix_spawn(&pid, argv[0].c_str(), &actions, nullptr, args.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  ::close(pipe_fds[1]);
  if (spawned != 0) {
    ::close(pipe_fds[0]);
    *err = std::strerror(spawned);
    return -1;
  }
  const int child_slot = remember_child(pid);
  bool stopped = false;
  auto stop_when_cancelled = [&] {
    if (stopped || !cancel || !cancel->load()) return;
    ::kill(pid, SIGTERM);
    stopped = true;
  };
  char buf[4096];
  for (ssize_t n; (n = ::read(pipe_fds[0], buf, sizeof buf)) != 0;) {
    stop_when_cancelled();
    if (n < 0) {
      if (errno == EINTR) continue;
      break;
    }
    err->append(buf, static_cast<size_t>(n));
    if (err->size() > (1u << 20)) err->erase(0, err->size() - (1u << 16));  // keep the tail
  }
  ::close(pipe_fds[0]);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0) {
    stop_when_cancelled();
    if (errno != EINTR) {
      forget_child(child_slot);
      return -1;
    }
  }
  forget_child(child_slot);
  if (WIFEXITED(status)) return WEXITSTATUS(status);
  return WIFSIGNALED(status) ? 128 + WTERMSIG(status) : -1;
}

// The last non-empty line of ffmpeg's messages.
std::string last_line(std::string text) {
  while (!text.empty() && (text.back() == '\n' || text.back() == '\r')) text.pop_back();
  const size_t nl = text.find_last_of('\n');
  return nl == std::string::npos ? text : text.substr(nl + 1);
}

}  // namespace

Status encode_video(const std::string& ffmpeg, const std::string& pattern, uint64_t first, uint64_t count, double fps,
                    const std::string& video, const std::atomic<bool>* cancel) {
  const std::optional<std::string> container = video_container_for(video);
  if (!container) return file_diagnostic(video, "not a video sylva encodes (.mp4, .mkv, .webm, .mov or .gif)");
  Expected<PendingFile> pending = PendingFile::create(video);
  if (!pending) return std::move(pending.error());
  std::vector<std::string> argv = {ffmpeg, "-nostdin", "-hide_banner", "-loglevel", "error", "-y",
                                   "-framerate", number_text(fps), "-start_number", std::to_string(first),
                                   "-i", ffmpeg_sequence_pattern(pattern), "-frames:v", std::to_string(count)};
  const char* even = "pad=ceil(iw/2)*2:ceil(ih/2)*2";
  if (*container == "gif") {
    argv.insert(argv.end(), {"-vf", "split[a][b];[a]palettegen[p];[b][p]paletteuse"});
  } else if (*container == "webm") {
    argv.insert(argv.end(), {"-vf", even, "-c:v", "libvpx-vp9", "-pix_fmt", "yuv420p"});
  } else {
    argv.insert(argv.end(), {"-vf", even, "-c:v", "libx264", "-pix_fmt", "yuv420p"});
  }
  argv.insert(argv.end(), {"-f", *container, pending->temporary()});
  std::string messages;
  const int status = run_child(argv, &messages, cancel);
  if (cancel && cancel->load()) return file_diagnostic(video, "interrupted: the video was not written");
  if (status != 0) {
    const std::string why = status < 0 ? "could not run " + ffmpeg + (messages.empty() ? "" : ": " + messages)
                                       : ffmpeg + " failed (exit " + std::to_string(status) + ")" +
                                             (messages.empty() ? "" : ": " + last_line(messages));
    return file_diagnostic(video, "cannot encode the video: " + why);
  }
  if (Status synced = pending->sync(); !synced) return synced;
  std::vector<PendingFile> files;
  files.push_back(std::move(*pending));
  return commit_files(files);
}

}  // namespace sylva::cli
