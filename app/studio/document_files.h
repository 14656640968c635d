// document_files.h — what the studio does with files (docs/spec/studio.md "Never blocking, never
// losing work"): saves are atomic (write_file_atomically, docs/spec/cli.md), an edited document is
// autosaved beside itself as `.NAME.autosave`, and a file's identity on disk (inode,
// mtime, ctime, size) is remembered so a change by another program is noticed.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

namespace sylva::studio {

// `.NAME.autosave` in the folder of `path` (the same for an untitled document's
// fallback name, e.g. "untitled.lsys" in the working folder).
std::string autosave_path(const std::string& path);

// What a file looked like on disk, to notice changes made by others. The times alone are
// not enough: a file system's clock may tick every few milliseconds (or every second), so
// two same-sized writes within one tick look alike. An atomic replacement (an editor's
// save, write_file_atomically, `git checkout`) always brings a new inode — the old one is
// still in use until the rename — so the device and inode catch those; ctime catches a
// change of the file's status by chmod or an in-place write in a later tick.
struct FileStamp {
  uint64_t device = 0, inode = 0;
  int64_t mtime_ns = 0, ctime_ns = 0;
  int64_t size = -1;  // -1: no such file
  bool operator==(const FileStamp&) const = default;
};
FileStamp stamp_of(const std::string& path);

// An autosave of `path` that should be offered for restoring: it exists and holds
// something other than the file's text — whether newer than the file or older (the file
// changed since, say by a `git checkout`: the edits are still the user's, and the next
// autosave would otherwise replace them unseen).
struct Autosave {
  std::string text;
  bool older_than_file = false;
};
std::optional<Autosave> restorable_autosave(const std::string& path, const std::string& file_text);

// The file a save of `path` writes: `path` itself, or, when it is a symbolic link, the
// file it leads to (every link followed), so that saving a document opened through a link
// changes the real document and keeps the link. A dangling link gives the path it names.
std::string save_target(const std::string& path);

// Removes the autosave of `path` (after a save, or when the user discards the edits).
void remove_autosave(const std::string& path);

// The file name without its folder ("elm.lsys").
std::string base_name(const std::string& path);

}  // namespace sylva::studio
