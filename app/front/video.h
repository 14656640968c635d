// video.h — `sylva render --frames … --video OUT` (docs/animation.md): the frames already
// written as images, encoded into one video by Debian's `ffmpeg` when it is installed.
// sylva links no codec library: ffmpeg runs as a child process (no shell), reading the
// frames through its image-sequence input, and writes a temporary next to OUT that replaces
// OUT only once complete (file_io.h's PendingFile), so an interrupted or failed encode
// leaves OUT as it was.
#pragma once

#include <atomic>
#include <cstdint>
#include <optional>
#include <string>

#include "core/util/diagnostic.h"

namespace sylva::cli {

// The ffmpeg program on PATH, or nullopt when none is installed.
std::optional<std::string> find_ffmpeg();

// The container ffmpeg writes for `video`'s extension (.mp4 → "mp4", .mkv → "matroska",
// .webm → "webm", .mov → "mov", .gif → "gif"), or nullopt for any other extension.
std::optional<std::string> video_container_for(const std::string& video);

// `pattern` (an output pattern holding {frame}) as ffmpeg's image-sequence pattern: each
// {frame} as %04d (batch.h's kFramePatternDigits), every literal % doubled.
std::string ffmpeg_sequence_pattern(const std::string& pattern);

// Encodes frames first .. first + count − 1, written at `pattern` (expand_frame_pattern),
// at `fps` frames per second into `video` (check_output_path passed; container from
// video_container_for): H.264 (VP9 for .webm, a palette for .gif) with pixels padded to
// even sizes. Failure: a Diagnostic for `video` with ffmpeg's exit status and its last
// message; `video` is untouched then. `cancel` (Ctrl-C: render's SIGINT flag) becoming
// true stops ffmpeg; a SIGTERM or SIGHUP to sylva stops it too (file_io.h remember_child):
// either way no ffmpeg outlives sylva and no temporary is left.
Status encode_video(const std::string& ffmpeg, const std::string& pattern, uint64_t first, uint64_t count, double fps,
                    const std::string& video, const std::atomic<bool>* cancel = nullptr);

}  // namespace sylva::cli
