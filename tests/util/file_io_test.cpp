// Tests for core/file_io.h: whole-file reads and atomic writes.
//
// Failures are provoked for real: a read-only directory (run as an unprivileged user
// when the tests run as root, since root ignores permissions), a file size limit
// (RLIMIT_FSIZE) that makes write() fail part way, and a directory in the way of rename().
#include "core/util/file_io.h"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <thread>
#include <vector>

namespace sylva {
namespace {

using namespace std::string_literals;
namespace fs = std::filesystem;

class FileIoTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = ::testing::TempDir() + "sylva-file-io-test-XXXXXX";
    ASSERT_NE(::mkdtemp(pattern.data()), nullptr);
    directory_ = pattern;
    ::chmod(directory_.c_str(), 0755);  // traversable by an unprivileged child process
  }
  void TearDown() override {
    for (const auto& entry : fs::recursive_directory_iterator(directory_)) {
      if (entry.is_directory() && !entry.is_symlink()) ::chmod(entry.path().c_str(), 0755);
    }
    fs::remove_all(directory_);
  }

  std::string path(const std::string& name) const { return directory_ + "/" + name; }

  // Names in `dir`, sorted: shows whether a temporary file was left behind.
  static std::vector<std::string> entries(const std::string& dir) {
    std::vector<std::string> names;
    for (const auto& entry : fs::directory_iterator(dir)) names.push_back(entry.path().filename());
    std::sort(names.begin(), names.end());
    return names;
  }

  // Reads and writes without the code under test.
  static std::string contents(const std::string& file) {
    std::ifstream in(file, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  static void put(const std::string& file, const std::string& bytes) {
    std::ofstream out(file, std::ios::binary);
    out << bytes;
  }

  static mode_t permissions(const std::string& file) {
    struct stat info {};
    EXPECT_EQ(::stat(file.c_str(), &info), 0);
    return info.st_mode & 07777;
  }

  // Whether `message` is "<what> '<dir>/.<name>.tmp-<pid>-<counter>'<tail>": a failure
  // on the temporary file, whose name holds this process's id and a counter.
  static bool is_temporary_failure(const std::string& message, const std::string& what,
                                   const std::string& dir, const std::string& name,
                                   const std::string& tail) {
    const std::string prefix = what + " '" + dir + "/." + name + ".tmp-" + std::to_string(::getpid()) + "-";
    const std::string suffix = "'" + tail;
    if (message.size() < prefix.size() + suffix.size() + 1) return false;
    if (message.compare(0, prefix.size(), prefix) != 0) return false;
    if (message.compare(message.size() - suffix.size(), suffix.size(), suffix) != 0) return false;
    const std::string counter = message.substr(prefix.size(), message.size() - prefix.size() - suffix.size());
    return std::all_of(counter.begin(), counter.end(), [](char c) { return c >= '0' && c <= '9'; });
  }

  std::string directory_;
};

// ---- read_text_file ---------------------------------------------------------------

TEST_F(FileIoTest, ReadsEveryByteUntranslated) {
  const std::string bytes = "a\0b\r\nc\xFF\n"s;
  put(path("f"), bytes);
  const Expected<std::string> result = read_text_file(path("f"));
  ASSERT_TRUE(result.ok()) << result.error().format();
  EXPECT_EQ(*result, bytes);
}

TEST_F(FileIoTest, ReadsEmptyAndLargeFiles) {
  put(path("empty"), "");
  EXPECT_EQ(read_text_file(path("empty")).value(), "");
  std::string large;
  for (int i = 0; i < 300'000; ++i) large += static_cast<char>('a' + i % 26);
  put(path("large"), large);
  EXPECT_EQ(read_text_file(path("large")).value(), large);
}

TEST_F(FileIoTest, AMissingFileIsAnErrorNamingThePathAndTheReason) {
  const Expected<std::string> result = read_text_file(path("missing.json"));
  ASSERT_FALSE(result.ok());
  EXPECT_EQ(result.error().file, path("missing.json"));
  EXPECT_EQ(result.error().loc, SourceLoc{});
  EXPECT_EQ(result.error().error_number, ENOENT);
  EXPECT_EQ(result.error().format(),
            path("missing.json") + ": error: cannot open for reading: No such file or directory\n");
}

TEST_F(FileIoTest, ADirectoryIsNotReadable) {
  const Expected<std::string> result = read_text_file(directory_);
  ASSERT_FALSE(result.ok());
  EXPECT_EQ(result.error().error_number, EISDIR);
  EXPECT_EQ(result.error().format(), directory_ + ": error: cannot read: Is a directory\n");
}

// A NUL inside a path: the system would open the file named by the part before it
// (issue 32). Refused for reading and for writing, the file before it untouched.
TEST_F(FileIoTest, APathHoldingANulIsRefusedNotCutShort) {
  put(path("plant.lsys"), "axiom: F\n");
  const std::string with_nul = path("plant.lsys") + std::string(1, '\0') + ".missing";
  const Expected<std::string> read = read_text_file(with_nul);
  ASSERT_FALSE(read.ok());
  EXPECT_NE(read.error().message.find("NUL"), std::string::npos) << read.error().format();
  EXPECT_EQ(read.error().file, path("plant.lsys") + "?.missing");
  EXPECT_FALSE(check_output_path(with_nul).ok());
  EXPECT_FALSE(write_file_atomically(with_nul, "overwritten").ok());
  EXPECT_EQ(read_text_file(path("plant.lsys")).value(), "axiom: F\n");
}

// ---- write_file_atomically --------------------------------------------------------

TEST_F(FileIoTest, WritingCreatesAFileWithExactlyTheBytes) {
  const std::string bytes = "{\n\0\r\n}"s;
  EXPECT_TRUE(write_file_atomically(path("plant.skel.json"), bytes).ok());
  EXPECT_EQ(contents(path("plant.skel.json")), bytes);
  EXPECT_EQ(entries(directory_), std::vector<std::string>{"plant.skel.json"});
}

TEST_F(FileIoTest, WritingReplacesAnExistingFileAndLeavesNoTemporaryFile) {
  put(path("plant.skel.json"), "old contents, longer than the new ones");
  for (int i = 0; i < 5; ++i) {
    EXPECT_TRUE(write_file_atomically(path("plant.skel.json"), "new " + std::to_string(i)).ok());
  }
  EXPECT_EQ(contents(path("plant.skel.json")), "new 4");
  EXPECT_EQ(entries(directory_), std::vector<std::string>{"plant.skel.json"});
}

TEST_F(FileIoTest, NewFilesGetTheUsualPermissionsLessTheUmask) {
  const mode_t previous = ::umask(022);
  const Status error = write_file_atomically(path("new.json"), "x");
  ::umask(previous);
  EXPECT_TRUE(error.ok());
  EXPECT_EQ(permissions(path("new.json")), 0644u);
}

TEST_F(FileIoTest, ReplacingAFileKeepsItsPermissions) {
  put(path("private.json"), "old");
  ::chmod(path("private.json").c_str(), 0600);
  EXPECT_TRUE(write_file_atomically(path("private.json"), "new").ok());
  EXPECT_EQ(permissions(path("private.json")), 0600u);
  EXPECT_EQ(contents(path("private.json")), "new");
}

TEST_F(FileIoTest, AnUnwritableDirectoryLeavesTheExistingFileUntouched) {
  const std::string dir = path("read-only");
  ASSERT_EQ(::mkdir(dir.c_str(), 0755), 0);
  const std::string target = dir + "/plant.skel.json";
  put(target, "old contents");
  ::chmod(target.c_str(), 0666);  // the file is writable to anyone: the folder is what refuses
  ASSERT_EQ(::chmod(dir.c_str(), 0555), 0);

  std::string message;
  int error_number = 0;
  if (::geteuid() != 0) {
    const Status error = write_file_atomically(target, "new contents");
    ASSERT_FALSE(error.ok());
    message = error.error().format();
    error_number = error.error().error_number;
  } else {
    // Root ignores directory permissions: try as the unprivileged user "nobody".
    int pipe_fds[2];
    ASSERT_EQ(::pipe(pipe_fds), 0);
    const pid_t child = ::fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      ::close(pipe_fds[0]);
      if (::setgid(65534) != 0 || ::setuid(65534) != 0) ::_exit(2);
      const Status error = write_file_atomically(target, "new contents");
      if (error.ok()) ::_exit(1);
      const std::string report = std::to_string(error.error().error_number) + " " + error.error().format();
      if (::write(pipe_fds[1], report.data(), report.size()) < 0) ::_exit(3);
      ::_exit(0);
    }
    ::close(pipe_fds[1]);
    std::string report;
    char buffer[512];
    for (ssize_t n; (n = ::read(pipe_fds[0], buffer, sizeof buffer)) > 0;) report.append(buffer, n);
    ::close(pipe_fds[0]);
    int status = 0;
    ASSERT_EQ(::waitpid(child, &status, 0), child);
    ASSERT_TRUE(WIFEXITED(status));
    if (WEXITSTATUS(status) == 2) GTEST_SKIP() << "running as root and cannot drop privileges";
    ASSERT_EQ(WEXITSTATUS(status), 0) << "the write into a read-only directory succeeded";
    const size_t space = report.find(' ');
    error_number = std::stoi(report.substr(0, space));
    message = report.substr(space + 1);
  }
  EXPECT_EQ(error_number, EACCES);
  EXPECT_EQ(message, target + ": error: cannot create a temporary file in directory '" + dir +
                         "': Permission denied\n");
  EXPECT_EQ(contents(target), "old contents");
  EXPECT_EQ(entries(dir), std::vector<std::string>{"plant.skel.json"});
}

TEST_F(FileIoTest, AFailedWriteLeavesTheExistingFileUntouchedAndNoTemporaryFile) {
  const std::string target = path("plant.skel.json");
  put(target, "old contents");
  // Files may not grow past 16 bytes: write() stops part way with EFBIG.
  struct rlimit previous_limit {};
  ASSERT_EQ(::getrlimit(RLIMIT_FSIZE, &previous_limit), 0);
  struct rlimit small_limit = previous_limit;
  small_limit.rlim_cur = 16;
  auto* previous_handler = ::signal(SIGXFSZ, SIG_IGN);
  ASSERT_EQ(::setrlimit(RLIMIT_FSIZE, &small_limit), 0);
  const Status error = write_file_atomically(target, std::string(4096, 'x'));
  ::setrlimit(RLIMIT_FSIZE, &previous_limit);
  ::signal(SIGXFSZ, previous_handler);

  ASSERT_FALSE(error.ok());
  EXPECT_EQ(error.error().file, target);
  EXPECT_EQ(error.error().error_number, EFBIG);
  EXPECT_TRUE(is_temporary_failure(error.error().message, "cannot write temporary file", directory_,
                                   "plant.skel.json", ": File too large"))
      << error.error().message;
  EXPECT_EQ(contents(target), "old contents");
  EXPECT_EQ(entries(directory_), std::vector<std::string>{"plant.skel.json"});
}

TEST_F(FileIoTest, AFailedRenameRemovesTheTemporaryFile) {
  // A non-empty directory appears where the file should go after its temporary was
  // written: rename() cannot replace it.
  const std::string target = path("plant.skel.json");
  Expected<PendingFile> pending = write_pending_file(target, "new contents");
  ASSERT_TRUE(pending.ok());
  ASSERT_EQ(::mkdir(target.c_str(), 0755), 0);
  put(target + "/inside", "kept");
  std::vector<PendingFile> files;
  files.push_back(std::move(*pending));
  const Status error = commit_files(files);
  ASSERT_FALSE(error.ok());
  EXPECT_EQ(error.error().error_number, EISDIR);
  EXPECT_TRUE(is_temporary_failure(error.error().message, "cannot rename temporary file", directory_,
                                   "plant.skel.json", " over it: Is a directory"))
      << error.error().message;
  EXPECT_EQ(contents(target + "/inside"), "kept");
  EXPECT_EQ(entries(directory_), std::vector<std::string>{"plant.skel.json"});
}

TEST_F(FileIoTest, ADirectoryAtTheTargetIsRefusedBeforeAnythingIsWritten) {
  const std::string target = path("plant.skel.json");
  ASSERT_EQ(::mkdir(target.c_str(), 0755), 0);
  const Status error = write_file_atomically(target, "new contents");
  ASSERT_FALSE(error.ok());
  EXPECT_EQ(error.error().error_number, EISDIR);
  EXPECT_EQ(error.error().format(), target + ": error: cannot write: Is a directory\n");
  EXPECT_EQ(entries(directory_), std::vector<std::string>{"plant.skel.json"});
}

TEST_F(FileIoTest, AMissingDirectoryIsAnErrorNamingIt) {
  const std::string target = path("no-such-dir/plant.skel.json");
  const Status error = write_file_atomically(target, "x");
  ASSERT_FALSE(error.ok());
  EXPECT_EQ(error.error().error_number, ENOENT);
  EXPECT_EQ(error.error().format(), target + ": error: cannot create a temporary file in directory '" +
                                 path("no-such-dir") + "': No such file or directory\n");
  EXPECT_TRUE(entries(directory_).empty());
}

TEST_F(FileIoTest, AnEmptyPathOrADirectoryPathIsAnError) {
  const Status empty = write_file_atomically("", "x");
  ASSERT_FALSE(empty.ok());
  EXPECT_EQ(empty.error().format(), "error: cannot write: the path is empty\n");
  const Status slash = write_file_atomically(directory_ + "/", "x");
  ASSERT_FALSE(slash.ok());
  EXPECT_EQ(slash.error().format(), directory_ + "/: error: cannot write: Is a directory\n");
  EXPECT_TRUE(entries(directory_).empty());
}

TEST_F(FileIoTest, ARelativePathIsWrittenInTheCurrentDirectory) {
  const fs::path previous = fs::current_path();
  fs::current_path(directory_);
  const Status error = write_file_atomically("relative.json", "here");
  fs::current_path(previous);
  EXPECT_TRUE(error.ok());
  EXPECT_EQ(contents(path("relative.json")), "here");
  EXPECT_EQ(entries(directory_), std::vector<std::string>{"relative.json"});
}

TEST_F(FileIoTest, ALongFileNameStillFitsItsTemporaryName) {
  const std::string name = std::string(250, 'n') + ".json";  // 255 bytes, the limit
  EXPECT_TRUE(write_file_atomically(path(name), "long").ok());
  EXPECT_EQ(contents(path(name)), "long");
  EXPECT_EQ(entries(directory_), std::vector<std::string>{name});
}

TEST_F(FileIoTest, ASymbolicLinkIsReplacedNotWrittenThrough) {
  put(path("real.json"), "real");
  fs::create_symlink(path("real.json"), path("link.json"));
  EXPECT_TRUE(write_file_atomically(path("link.json"), "new").ok());
  EXPECT_FALSE(fs::is_symlink(path("link.json")));
  EXPECT_EQ(contents(path("link.json")), "new");
  EXPECT_EQ(contents(path("real.json")), "real");
}


// ---- hostile targets and inputs (docs/limits.md) ------------------------------------

TEST_F(FileIoTest, AFifoAtTheTargetIsRefusedAndStaysAFifo) {
  const std::string target = path("out.skel.json");
  ASSERT_EQ(::mkfifo(target.c_str(), 0644), 0);
  const Status error = write_file_atomically(target, "x");
  ASSERT_FALSE(error.ok());
  EXPECT_NE(error.error().message.find("it is a FIFO, and sylva writes regular files only"), std::string::npos)
      << error.error().message;
  EXPECT_TRUE(fs::is_fifo(target));
  EXPECT_EQ(entries(directory_), std::vector<std::string>{"out.skel.json"});
}

TEST_F(FileIoTest, ADeviceAtTheTargetIsRefused) {
  const Status error = write_file_atomically("/dev/null", "x");
  ASSERT_FALSE(error.ok());
  EXPECT_EQ(error.error().file, "/dev/null");
  EXPECT_NE(error.error().message.find("a character device"), std::string::npos) << error.error().message;
  EXPECT_TRUE(fs::is_character_file("/dev/null"));
}

TEST_F(FileIoTest, AReadOnlyFileIsNotReplaced) {
  const std::string target = path("kept.skel.json");
  put(target, "old");
  ::chmod(target.c_str(), 0444);
  const Status error = write_file_atomically(target, "new");
  ASSERT_FALSE(error.ok());
  EXPECT_EQ(error.error().error_number, EACCES);
  EXPECT_EQ(error.error().format(), target + ": error: cannot write: the file is read-only (Permission denied)\n");
  EXPECT_EQ(contents(target), "old");
  EXPECT_EQ(entries(directory_), std::vector<std::string>{"kept.skel.json"});
}

// In a child process: refuse_outputs_onto_inputs() holds for the whole process.
TEST_F(FileIoTest, AnInputIsNeverOverwrittenUnderAnyOfItsNames) {
  put(path("a.lsys"), "axiom: A\n");
  ASSERT_EQ(::link(path("a.lsys").c_str(), path("hard.lsys").c_str()), 0);
  put(path("other.lsys"), "other");
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    refuse_outputs_onto_inputs();
    if (!read_text_file(path("a.lsys")).ok()) ::_exit(10);
    if (write_file_atomically(directory_ + "/./a.lsys", "x").ok()) ::_exit(11);
    const Status via_link = write_file_atomically(path("hard.lsys"), "x");
    if (via_link.ok() || via_link.error().message.find("it is an input of this command") == std::string::npos)
      ::_exit(12);
    if (!write_file_atomically(path("other.lsys"), "new").ok()) ::_exit(13);  // not read: writable
    ::_exit(0);
  }
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0);
  EXPECT_EQ(contents(path("a.lsys")), "axiom: A\n");
  EXPECT_EQ(contents(path("other.lsys")), "new");
}

TEST_F(FileIoTest, WithoutTheRefusalAFileReadMayBeSavedOver) {  // the studio saving its document
  put(path("doc.lsys"), "old");
  ASSERT_TRUE(read_text_file(path("doc.lsys")).ok());
  EXPECT_TRUE(write_file_atomically(path("doc.lsys"), "new").ok());
  EXPECT_EQ(contents(path("doc.lsys")), "new");
}

TEST_F(FileIoTest, ADeviceIsNotReadWithoutBound) {
  const Expected<std::string> zero = read_text_file("/dev/zero");
  ASSERT_FALSE(zero.ok());
  EXPECT_EQ(zero.error().format(),
            "/dev/zero: error: cannot read: it is a character device, not a regular file or a pipe "
            "(docs/limits.md)\n");
}

TEST_F(FileIoTest, AFileOverTheLimitIsRefusedBeforeReading) {
  put(path("big.lsys"), std::string(2000, 'x'));
  const Expected<std::string> big = read_text_file(path("big.lsys"), 1000);
  ASSERT_FALSE(big.ok());
  EXPECT_EQ(big.error().message,
            "cannot read: the file has 2000 bytes, more than the limit of 1000 bytes (docs/limits.md)");
  EXPECT_TRUE(read_text_file(path("big.lsys"), 2000).ok());
}

TEST_F(FileIoTest, APipeIsReadUpToTheLimitOnly) {
  const std::string fifo = path("pipe.lsys");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0644), 0);
  // A writer that never stops (a pipe from /dev/zero): the reader must give up by itself.
  std::thread writer([&] {
    const int fd = ::open(fifo.c_str(), O_WRONLY);
    if (fd < 0) return;
    ::signal(SIGPIPE, SIG_IGN);
    const std::string chunk(4096, 'z');
    while (::write(fd, chunk.data(), chunk.size()) > 0) {
    }
    ::close(fd);
  });
  const Expected<std::string> read = read_text_file(fifo, 1 << 20);
  writer.join();
  ASSERT_FALSE(read.ok());
  EXPECT_EQ(read.error().message, "cannot read: it holds more than the limit of 1 MiB (docs/limits.md)");
}

TEST_F(FileIoTest, SeveralOutputsAreAllWrittenBeforeAnyIsReplaced) {
  put(path("a.png"), "old a");
  put(path("b.exr"), "old b");
  ::chmod(path("b.exr").c_str(), 0444);
  std::vector<PendingFile> files;
  Expected<PendingFile> a = write_pending_file(path("a.png"), "new a");
  ASSERT_TRUE(a.ok());
  files.push_back(std::move(*a));
  Expected<PendingFile> b = write_pending_file(path("b.exr"), "new b");
  EXPECT_FALSE(b.ok());  // read-only: the run stops before any rename
  files.clear();         // dropped uncommitted: the temporaries go
  EXPECT_EQ(contents(path("a.png")), "old a");
  EXPECT_EQ(entries(directory_), (std::vector<std::string>{"a.png", "b.exr"}));

  ::chmod(path("b.exr").c_str(), 0644);
  for (const char* name : {"a.png", "b.exr"}) {
    Expected<PendingFile> f = write_pending_file(path(name), std::string("new ") + name[0]);
    ASSERT_TRUE(f.ok());
    files.push_back(std::move(*f));
  }
  EXPECT_TRUE(commit_files(files).ok());
  EXPECT_EQ(contents(path("a.png")), "new a");
  EXPECT_EQ(contents(path("b.exr")), "new b");
  EXPECT_EQ(entries(directory_), (std::vector<std::string>{"a.png", "b.exr"}));
}

TEST_F(FileIoTest, ASignalDuringAWriteRemovesTheTemporary) {
  for (int signal_number : {SIGINT, SIGTERM}) {
    int report[2];
    ASSERT_EQ(::pipe(report), 0);
    const pid_t child = ::fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      remove_temporaries_on_signals();
      Expected<PendingFile> pending = write_pending_file(path("out.glb"), "half");
      if (!pending.ok()) ::_exit(10);
      const std::string name = pending->temporary();
      if (::write(report[1], name.data(), name.size()) != static_cast<ssize_t>(name.size())) ::_exit(11);
      ::close(report[1]);
      ::raise(signal_number);
      ::_exit(12);  // not reached: the handler ends the process by the signal
    }
    ::close(report[1]);
    char name[4096] = {};
    const ssize_t n = ::read(report[0], name, sizeof name - 1);
    ::close(report[0]);
    int status = 0;
    ASSERT_EQ(::waitpid(child, &status, 0), child);
    ASSERT_GT(n, 0);
    ASSERT_TRUE(WIFSIGNALED(status)) << status;
    EXPECT_EQ(WTERMSIG(status), signal_number);
    EXPECT_FALSE(fs::exists(name)) << name;
    EXPECT_TRUE(entries(directory_).empty());
  }
}

}  // namespace
}  // namespace sylva
