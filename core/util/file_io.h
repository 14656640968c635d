// file_io.h — reading and writing whole files, with errors as values.
//
// Every front end reads grammars and skeletons and writes results through these two
// functions, so a failure always reads the same way: the path, what was being done,
// and the system's reason ("strerror").
#pragma once

#include <optional>
#include <string>
#include <string_view>

namespace sylva {

// Why a file operation failed.
struct FileError {
  std::string path;      // the path as the caller gave it
  std::string message;   // what failed and why: "cannot open for reading: No such file or directory"
  int error_number = 0;  // errno of the failing system call; 0 if none was involved
  std::string format() const;  // "path: error: message"
};

// Result of read_text_file: the file's bytes, or why they could not be read.
struct FileReadResult {
  std::optional<std::string> contents;
  std::optional<FileError> error;
};

// Reads the whole file at `path` to its end, byte for byte (no newline or encoding translation;
// NUL bytes are kept). A missing or unreadable file, a directory, or a read error is a
// FileError naming `path` and the system's reason.
FileReadResult read_text_file(const std::string& path);

// Replaces the file at `path` with `bytes` so that readers see either the old file or
// the complete new one, never a mix or a truncated file:
//   1. creates a new temporary file ".<name>.tmp-<pid>-<counter>" in the same directory
//      (O_CREAT | O_EXCL, so it never reuses someone else's file; permission bits 0666
//      minus the umask, or the rwx bits of the existing regular file at `path`);
//   2. writes all of `bytes`, fsyncs and closes it;
//   3. rename()s it over `path` (atomic within one file system), then fsyncs the
//      directory (best effort) so the rename survives a crash.
// On any failure the temporary file is removed and an existing file at `path` is left
// untouched; the FileError names `path`, the failing step and the system's reason.
// A symbolic link at `path` is replaced by the new file, not written through; the
// owner of an existing file is not carried over. An empty `path` or one ending in '/'
// is an error.
std::optional<FileError> write_file_atomically(const std::string& path, std::string_view bytes);

}  // namespace sylva
