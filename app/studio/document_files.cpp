// document_files.cpp — see document_files.h.
#include "app/studio/document_files.h"

#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>

#include "core/util/file_io.h"

namespace sylva::studio {

std::string base_name(const std::string& path) { return std::filesystem::path(path).filename().string(); }

std::string autosave_path(const std::string& path) {
  const std::filesystem::path p(path);
  return (p.parent_path() / ("." + p.filename().string() + ".autosave")).string();
}

FileStamp stamp_of(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return {};
  FileStamp s;
  s.device = static_cast<uint64_t>(st.st_dev);
  s.inode = static_cast<uint64_t>(st.st_ino);
  s.mtime_ns = static_cast<int64_t>(st.st_mtim.tv_sec) * 1000000000 + st.st_mtim.tv_nsec;
  s.ctime_ns = static_cast<int64_t>(st.st_ctim.tv_sec) * 1000000000 + st.st_ctim.tv_nsec;
  s.size = static_cast<int64_t>(st.st_size);
  return s;
}

std::optional<Autosave> restorable_autosave(const std::string& path, const std::string& file_text) {
  const std::string a = autosave_path(path);
  const FileStamp as = stamp_of(a), fs = stamp_of(path);
  if (as.size < 0) return std::nullopt;
  Expected<std::string> r = read_text_file(a);
  if (!r || *r == file_text) return std::nullopt;
  return Autosave{std::move(*r), fs.size >= 0 && as.mtime_ns < fs.mtime_ns};
}

std::string save_target(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code error;
  if (!fs::is_symlink(fs::symlink_status(path, error))) return path;
  const fs::path real = fs::weakly_canonical(fs::absolute(path, error), error);
  return error ? path : real.string();
}

void remove_autosave(const std::string& path) { ::unlink(autosave_path(path).c_str()); }

}  // namespace sylva::studio
