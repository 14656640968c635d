// file_io.h — reading and writing whole files, with errors as values.
//
// Every front end reads grammars and skeletons and writes results through these two
// functions, so a failure always reads the same way: the path, what was being done,
// and the system's reason ("strerror"), as a Diagnostic (diagnostic.h) with the errno.
#pragma once

#include <string>
#include <string_view>

#include "core/util/diagnostic.h"

namespace sylva {

// Reads the whole file at `path` to its end, byte for byte (no newline or encoding translation;
// NUL bytes are kept). A missing or unreadable file, a directory, or a read error is a
// Diagnostic for `path` as a whole (file_diagnostic) with what failed and the system's
// reason ("cannot open for reading: No such file or directory") and its errno.
Expected<std::string> read_text_file(const std::string& path);

// Replaces the file at `path` with `bytes` so that readers see either the old file or
// the complete new one, never a mix or a truncated file:
//   1. creates a new temporary file ".<name>.tmp-<pid>-<counter>" in the same directory
//      (O_CREAT | O_EXCL, so it never reuses someone else's file; permission bits 0666
//      minus the umask, or the rwx bits of the existing regular file at `path`);
//   2. writes all of `bytes`, fsyncs and closes it;
//   3. rename()s it over `path` (atomic within one file system), then fsyncs the
//      directory (best effort) so the rename survives a crash.
// On any failure the temporary file is removed and an existing file at `path` is left
// untouched; the Diagnostic names `path`, the failing step and the system's reason, and
// carries its errno.
// A symbolic link at `path` is replaced by the new file, not written through; the
// owner of an existing file is not carried over. An empty `path` or one ending in '/'
// is an error.
Status write_file_atomically(const std::string& path, std::string_view bytes);

}  // namespace sylva
