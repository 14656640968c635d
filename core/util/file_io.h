// file_io.h — reading and writing whole files, with errors as values.
//
// Every front end reads grammars and skeletons and writes results through these two
// functions, so a failure always reads the same way: the path, what was being done,
// and the system's reason ("strerror"), as a Diagnostic (diagnostic.h) with the errno.
#pragma once

#include <sys/types.h>

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "core/util/diagnostic.h"

namespace sylva {

// The most bytes read_text_file reads by default (docs/limits.md): 1 GiB.
inline constexpr size_t kMaxInputFileBytes = size_t{1} << 30;

// Reads the whole file at `path` to its end, byte for byte (no newline or encoding translation;
// NUL bytes are kept). Only a regular file or a pipe (FIFO, `<(...)`) is read, and at most
// `max_bytes` of it: a regular file larger than that is refused before anything is read, a
// pipe as soon as it gives more (docs/limits.md). A missing or unreadable file, a directory,
// a device (/dev/zero) or socket, a file over the limit, or a read error is a Diagnostic for
// `path` as a whole (file_diagnostic) with what failed and the system's reason ("cannot open
// for reading: No such file or directory") and its errno. The file is noted as an input
// (note_input_file).
Expected<std::string> read_text_file(const std::string& path, size_t max_bytes = kMaxInputFileBytes);

// Outputs never replace an input of the same run (docs/limits.md, "Outputs"). Once
// refuse_outputs_onto_inputs() was called (the `sylva` command does, first), every file
// noted as an input — by read_text_file, or by note_input_file for files read otherwise
// (images) — is remembered by device and inode, and every later write to the same file
// (whatever its name: "./a.lsys", a hard link) is refused. Without the call nothing is
// remembered (the studio saves over the document it read). Thread-safe.
void refuse_outputs_onto_inputs();
void note_input_file(const std::string& path);

// The same rule for a front end that keeps no process-wide list (Python: a session reads
// and writes many files over its life): a Diagnostic when `output` is the same file as one
// of `inputs` — the files the output is made from, compared by device and inode, whatever
// their names — else success. A symbolic link at `output` is replaced, never written
// through, so it is compared itself.
Status check_not_an_input(const std::string& output, const std::vector<std::string>& inputs);

// A path holding a NUL character names no file: the system would take the part before
// it, another file. A Diagnostic for it (the NULs shown as '?'), else success.
// read_text_file, check_output_path and check_image_opens refuse such a path with it.
Status check_path_has_no_nul(const std::string& path);

// Whether `path` may be written as an output (docs/limits.md, "Outputs"): a missing file, a
// regular file that is writable (not `chmod a-w`, and writable to this user), or a
// symbolic link (replaced, see below) — and never a file noted as an input. A FIFO, a
// device (/dev/null), a socket or a directory at `path` is refused, never replaced or written
// through. Failure: a Diagnostic for `path` saying which rule and why.
Status check_output_path(const std::string& path);

// A temporary file, complete and on disk, waiting to be renamed over its target: the
// first half of an atomic write, so that several outputs can all be written before any of
// them replaces a file (commit_files). Removes the temporary when destroyed uncommitted.
// While it exists an interrupt (remove_temporaries_on_signals) removes it too.
class PendingFile {
 public:
  PendingFile() = default;
  PendingFile(PendingFile&& other) noexcept;
  PendingFile& operator=(PendingFile&& other) noexcept;
  PendingFile(const PendingFile&) = delete;
  PendingFile& operator=(const PendingFile&) = delete;
  ~PendingFile();

  const std::string& target() const { return target_; }
  const std::string& temporary() const { return temporary_; }

  // Creates the temporary for `target` in its folder, empty (check_output_path first), with
  // the permission bits of the file it replaces; the caller (an image writer) fills it.
  static Expected<PendingFile> create(const std::string& target);
  // Syncs the filled temporary to disk (before commit).
  Status sync() const;

 private:
  friend Status commit_files(std::vector<PendingFile>& files);
  void discard();
  std::string target_;
  std::string temporary_;
  int slot_ = -1;  // its place in the interrupt list, -1 when none
};

// create() + writes `bytes` + sync(): a complete temporary for `target`.
Expected<PendingFile> write_pending_file(const std::string& target, std::string_view bytes);

// Renames every temporary over its target, in order, then syncs their folders (best
// effort). All were checked and written before the first rename, so either every target
// is replaced or — when the very first write failed — none; a rename that fails part way
// (another process changed the folder) leaves the targets before it replaced and removes
// the rest of the temporaries. The Diagnostic names the target that failed.
Status commit_files(std::vector<PendingFile>& files);

// Installs SIGINT, SIGTERM and SIGHUP handlers that remove every pending temporary of the
// process and then end it as the signal would have (the `sylva` command calls it first).
// A handler set later (render's SIGINT, which cancels the render) takes precedence while set.
void remove_temporaries_on_signals();
// A child process writing a pending temporary (ffmpeg encoding a video): until
// forget_child(slot), those handlers first send it SIGTERM and reap it, so it never
// outlives sylva to write the temporary after it was removed. Returns the slot (-1 when
// all 16 are taken: the child is then not stopped by a signal).
int remember_child(pid_t pid);
void forget_child(int slot);

// Replaces the file at `path` with `bytes` so that readers see either the old file or
// the complete new one, never a mix or a truncated file:
//   1. creates a new temporary file ".<name>.tmp-<pid>-<counter>" in the same directory
//      (O_CREAT | O_EXCL, so it never reuses someone else's file; permission bits 0666
//      minus the umask, or the rwx bits of the existing regular file at `path`);
//   2. writes all of `bytes`, fsyncs and closes it;
//   3. rename()s it over `path` (atomic within one file system), then fsyncs the
//      directory (best effort) so the rename survives a crash.
// `path` must pass check_output_path. On any failure the temporary file is removed and an
// existing file at `path` is left untouched; the Diagnostic names `path`, the failing step and the system's reason, and
// carries its errno.
// A symbolic link at `path` is replaced by the new file, not written through; the
// owner of an existing file is not carried over. An empty `path` or one ending in '/'
// is an error.
Status write_file_atomically(const std::string& path, std::string_view bytes);

}  // namespace sylva
