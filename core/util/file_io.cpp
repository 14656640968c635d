// file_io.cpp — whole-file reads and atomic whole-file writes (POSIX).
//
// The atomic write is the classic "write a temporary file, fsync, rename over the
// target" sequence: rename() within one directory replaces the name atomically, so an
// interrupted run or a full disk never leaves a truncated plant file behind.
#include "core/util/file_io.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <sys/types.h>
#include <unistd.h>

#include <signal.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <climits>
#include <cstdint>
#include <cstring>
#include <mutex>
#include <set>
#include <system_error>
#include <utility>

namespace sylva {
namespace {

Diagnostic errno_error(const std::string& path, const std::string& what, int error_number) {
  return file_diagnostic(path, what + ": " + std::generic_category().message(error_number), error_number);
}

// Keeps the temporary name within NAME_MAX (255) however long the target's name is.
constexpr size_t kMaxNameInTemporary = 200;

// write() may write less than asked (signals, pipes, RLIMIT_FSIZE); loop until done.
bool write_all(int fd, std::string_view bytes) {
  size_t written = 0;
  while (written < bytes.size()) {
    const size_t chunk = std::min<size_t>(bytes.size() - written, size_t{1} << 30);
    const ssize_t n = ::write(fd, bytes.data() + written, chunk);
    if (n < 0) {
      if (errno == EINTR) continue;
      return false;
    }
    if (n == 0) {
      errno = EIO;
      return false;
    }
    written += static_cast<size_t>(n);
  }
  return true;
}

// What kind of file a stat() describes, for messages ("a FIFO").
const char* kind_of(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a regular file";
}

std::string mib(size_t bytes) {
  return bytes % (size_t{1} << 20) == 0 ? std::to_string(bytes >> 20) + " MiB" : std::to_string(bytes) + " bytes";
}

// The inputs of this run by (device, inode), once refuse_outputs_onto_inputs() was called.
struct InputFiles {
  std::mutex mutex;
  bool enabled = false;
  std::set<std::pair<dev_t, ino_t>> files;
};
InputFiles& input_files() {
  static InputFiles* files = new InputFiles;  // never destroyed: used until exit
  return *files;
}

// Pending temporaries, for the signal handler: fixed slots, so that the handler only reads
// memory that is never freed and calls nothing but unlink() (async-signal-safe).
constexpr int kTemporarySlots = 128;
struct TemporarySlot {
  std::atomic<int> state{0};  // 0 free, 1 being filled, 2 holds a path
  char path[PATH_MAX];
};
TemporarySlot g_temporaries[kTemporarySlots];

int remember_temporary(const std::string& path) {
  if (path.size() >= PATH_MAX) return -1;
  for (int i = 0; i < kTemporarySlots; ++i) {
    int expected = 0;
    if (!g_temporaries[i].state.compare_exchange_strong(expected, 1)) continue;
    std::memcpy(g_temporaries[i].path, path.c_str(), path.size() + 1);
    g_temporaries[i].state.store(2);
    return i;
  }
  return -1;  // more pending at once than slots: still removed on every path but a signal
}

void forget_temporary(int slot) {
  if (slot >= 0) g_temporaries[slot].state.store(0);
}

// Child processes that write a pending temporary (ffmpeg), for the same handler: stopped
// and reaped before the temporaries are removed, so none outlives sylva to write one again.
constexpr int kChildSlots = 16;
std::atomic<pid_t> g_children[kChildSlots];

extern "C" void remove_temporaries_and_reraise(int signal_number) {
  const int saved_errno = errno;
  for (std::atomic<pid_t>& child : g_children)
    if (const pid_t pid = child.load(); pid > 0) {
      ::kill(pid, SIGTERM);  // kill() and waitpid() are async-signal-safe
      while (::waitpid(pid, nullptr, 0) < 0 && errno == EINTR) {
      }
    }
  for (TemporarySlot& slot : g_temporaries)
    if (slot.state.load() == 2) ::unlink(slot.path);
  errno = saved_errno;
  ::signal(signal_number, SIG_DFL);
  ::raise(signal_number);
}

void split_path(const std::string& path, std::string* directory_prefix, std::string* directory, std::string* name) {
  const size_t slash = path.rfind('/');
  *directory_prefix = slash == std::string::npos ? "" : path.substr(0, slash + 1);
  *directory = slash == std::string::npos ? "." : slash == 0 ? "/" : path.substr(0, slash);
  *name = path.substr(directory_prefix->size());
}

void sync_directory(const std::string& directory) {
  // Makes a rename durable; the data is already safe, so failure here is not reported
  // (some file systems refuse fsync on directories).
  const int directory_fd = ::open(directory.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (directory_fd >= 0) {
    (void)::fsync(directory_fd);
    ::close(directory_fd);
  }
}

}  // namespace

void refuse_outputs_onto_inputs() {
  InputFiles& inputs = input_files();
  std::lock_guard<std::mutex> lock(inputs.mutex);
  inputs.enabled = true;
}

void note_input_file(const std::string& path) {
  InputFiles& inputs = input_files();
  std::lock_guard<std::mutex> lock(inputs.mutex);
  struct stat info {};
  if (inputs.enabled && ::stat(path.c_str(), &info) == 0) inputs.files.insert({info.st_dev, info.st_ino});
}

Status check_not_an_input(const std::string& output, const std::vector<std::string>& inputs) {
  struct stat out {};
  if (output.empty() || ::lstat(output.c_str(), &out) != 0) return {};  // a new file is nobody's input
  for (const std::string& input : inputs) {
    struct stat in {};
    if (!input.empty() && ::stat(input.c_str(), &in) == 0 && in.st_dev == out.st_dev && in.st_ino == out.st_ino)
      return file_diagnostic(output, "cannot write: it is " + (input == output ? std::string("an input") : "'" + input + "'") +
                                         " of this call, which writing would destroy");
  }
  return {};
}

Status check_path_has_no_nul(const std::string& path) {
  if (path.find('\0') == std::string::npos) return {};
  std::string shown = path;
  std::replace(shown.begin(), shown.end(), '\0', '?');
  return file_diagnostic(shown, "the path holds a NUL character, which no file name does (the system would open "
                                "the file named by the part before it)");
}

Status check_output_path(const std::string& path) {
  if (path.empty()) return file_diagnostic(path, "cannot write: the path is empty");
  if (Status named = check_path_has_no_nul(path); !named) return named;
  if (path.back() == '/') return errno_error(path, "cannot write", EISDIR);
  struct stat info {};
  if (::lstat(path.c_str(), &info) != 0) {
    if (errno == ENOENT) return {};  // a new file (a missing folder fails when it is created)
    return errno_error(path, "cannot write", errno);
  }
  {
    InputFiles& inputs = input_files();
    std::lock_guard<std::mutex> lock(inputs.mutex);
    if (inputs.files.count({info.st_dev, info.st_ino}))
      return file_diagnostic(path, "cannot write: it is an input of this command, which writing would destroy");
  }
  if (S_ISLNK(info.st_mode)) return {};
  if (S_ISDIR(info.st_mode)) return errno_error(path, "cannot write", EISDIR);
  if (!S_ISREG(info.st_mode))
    return file_diagnostic(path, std::string("cannot write: it is ") + kind_of(info.st_mode) +
                                     ", and sylva writes regular files only (docs/limits.md, \"Outputs\")");
  if ((info.st_mode & 0222) == 0 || ::access(path.c_str(), W_OK) != 0)
    return file_diagnostic(path, "cannot write: the file is read-only (" +
                                     std::generic_category().message(EACCES) + ")", EACCES);
  return {};
}

PendingFile::PendingFile(PendingFile&& other) noexcept
    : target_(std::move(other.target_)), temporary_(std::move(other.temporary_)),
      slot_(std::exchange(other.slot_, -1)) {
  other.temporary_.clear();
}

PendingFile& PendingFile::operator=(PendingFile&& other) noexcept {
  if (this != &other) {
    discard();
    target_ = std::move(other.target_);
    temporary_ = std::move(other.temporary_);
    other.temporary_.clear();
    slot_ = std::exchange(other.slot_, -1);
  }
  return *this;
}

PendingFile::~PendingFile() { discard(); }

void PendingFile::discard() {
  if (!temporary_.empty()) ::unlink(temporary_.c_str());
  forget_temporary(slot_);
  slot_ = -1;
  temporary_.clear();
}

Expected<PendingFile> PendingFile::create(const std::string& target) {
  if (Status allowed = check_output_path(target); !allowed) return std::move(allowed.error());
  std::string directory_prefix, directory, name;
  split_path(target, &directory_prefix, &directory, &name);

  // Keep the permission bits (not set-user/group-ID) of the file being replaced.
  struct stat existing {};
  const bool replaces_regular_file = ::lstat(target.c_str(), &existing) == 0 && S_ISREG(existing.st_mode);

  static std::atomic<uint64_t> counter{0};
  PendingFile pending;
  pending.target_ = target;
  std::string temporary;
  int fd = -1;
  for (int attempt = 0; attempt < 100 && fd < 0; ++attempt) {
    temporary = directory_prefix + "." + name.substr(0, kMaxNameInTemporary) + ".tmp-" +
                std::to_string(::getpid()) + "-" + std::to_string(counter.fetch_add(1));
    fd = ::open(temporary.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd < 0 && errno != EEXIST) break;
  }
  if (fd < 0) {
    const int error_number = errno;
    return errno_error(target, "cannot create a temporary file in directory '" + directory + "'", error_number);
  }
  pending.temporary_ = temporary;
  pending.slot_ = remember_temporary(temporary);
  if (replaces_regular_file) (void)::fchmod(fd, existing.st_mode & 0777);  // before any data
  if (::close(fd) != 0) return errno_error(target, "cannot close temporary file '" + temporary + "'", errno);
  return pending;
}

Status PendingFile::sync() const {
  const int fd = ::open(temporary_.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0 || ::fsync(fd) != 0) {
    const int error_number = errno;
    if (fd >= 0) ::close(fd);
    return errno_error(target_, "cannot flush temporary file '" + temporary_ + "' to disk", error_number);
  }
  ::close(fd);
  return {};
}

Expected<PendingFile> write_pending_file(const std::string& target, std::string_view bytes) {
  Expected<PendingFile> pending = PendingFile::create(target);
  if (!pending) return pending;
  const std::string& temporary = pending->temporary();
  // `error_number` is errno read right after the failing call, before any allocation.
  auto fail = [&](int error_number, const char* what, const char* after_name) {
    return errno_error(target, std::string(what) + " '" + temporary + "'" + after_name, error_number);
  };
  const int fd = ::open(temporary.c_str(), O_WRONLY | O_TRUNC | O_CLOEXEC);
  if (fd < 0) return fail(errno, "cannot open temporary file", "");
  if (!write_all(fd, bytes)) {
    const int error_number = errno;
    ::close(fd);
    return fail(error_number, "cannot write temporary file", "");
  }
  if (::fsync(fd) != 0) {
    const int error_number = errno;
    ::close(fd);
    return fail(error_number, "cannot flush temporary file", " to disk");
  }
  if (::close(fd) != 0) return fail(errno, "cannot close temporary file", "");
  return pending;
}

Status commit_files(std::vector<PendingFile>& files) {
  std::set<std::string> directories;
  for (PendingFile& f : files) {
    if (::rename(f.temporary_.c_str(), f.target_.c_str()) != 0) {
      const int error_number = errno;
      Diagnostic error = errno_error(f.target_, "cannot rename temporary file '" + f.temporary_ + "' over it",
                                     error_number);
      for (PendingFile& rest : files) rest.discard();
      return error;
    }
    forget_temporary(f.slot_);
    f.slot_ = -1;
    f.temporary_.clear();
    std::string prefix, directory, name;
    split_path(f.target_, &prefix, &directory, &name);
    directories.insert(directory);
  }
  for (const std::string& d : directories) sync_directory(d);
  return {};
}

int remember_child(pid_t pid) {
  for (int i = 0; i < kChildSlots; ++i) {
    pid_t expected = 0;
    if (g_children[i].compare_exchange_strong(expected, pid)) return i;
  }
  return -1;
}

void forget_child(int slot) {
  if (slot >= 0) g_children[slot].store(0);
}

void remove_temporaries_on_signals() {
  for (int signal_number : {SIGINT, SIGTERM, SIGHUP}) {
    struct sigaction action {};
    action.sa_handler = remove_temporaries_and_reraise;
    sigemptyset(&action.sa_mask);
    sigaction(signal_number, &action, nullptr);
  }
}

Expected<std::string> read_text_file(const std::string& path, size_t max_bytes) {
  if (Status named = check_path_has_no_nul(path); !named) return std::move(named.error());
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) {
    const int error_number = errno;  // before anything that may allocate
    return errno_error(path, "cannot open for reading", error_number);
  }

  struct stat info {};
  if (::fstat(fd, &info) != 0) {
    const int error_number = errno;
    ::close(fd);
    return errno_error(path, "cannot read", error_number);
  }
  if (S_ISDIR(info.st_mode)) {
    ::close(fd);
    return errno_error(path, "cannot read", EISDIR);
  }
  if (!S_ISREG(info.st_mode) && !S_ISFIFO(info.st_mode)) {
    ::close(fd);
    return file_diagnostic(path, std::string("cannot read: it is ") + kind_of(info.st_mode) +
                                     ", not a regular file or a pipe (docs/limits.md)");
  }
  if (S_ISREG(info.st_mode) && static_cast<uint64_t>(info.st_size) > max_bytes) {
    ::close(fd);
    return file_diagnostic(path, "cannot read: the file has " + std::to_string(info.st_size) +
                                     " bytes, more than the limit of " + mib(max_bytes) + " (docs/limits.md)");
  }
  note_input_file(path);

  std::string contents;
  if (S_ISREG(info.st_mode) && info.st_size > 0) contents.reserve(static_cast<size_t>(info.st_size));
  char buffer[1 << 16];
  for (;;) {  // to end of file, not to st_size: the file may change, /proc files have none
    const ssize_t n = ::read(fd, buffer, sizeof buffer);
    if (n == 0) break;
    if (n < 0) {
      if (errno == EINTR) continue;
      const int error_number = errno;
      ::close(fd);
      return errno_error(path, "cannot read", error_number);
    }
    if (contents.size() + static_cast<size_t>(n) > max_bytes) {
      ::close(fd);
      return file_diagnostic(path, "cannot read: it holds more than the limit of " + mib(max_bytes) +
                                       " (docs/limits.md)");
    }
    contents.append(buffer, static_cast<size_t>(n));
  }
  ::close(fd);
  return contents;
}

Status write_file_atomically(const std::string& path, std::string_view bytes) {
  Expected<PendingFile> pending = write_pending_file(path, bytes);
  if (!pending) return std::move(pending.error());
  std::vector<PendingFile> files;
  files.push_back(std::move(*pending));
  return commit_files(files);
}

}  // namespace sylva
